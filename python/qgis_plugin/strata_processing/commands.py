"""Ingest DEM to store and Render picture: the installed `strata ingest` and `strata render`,
started with an argument list (no shell), their output in the log, their one-line error as the
algorithm's, QGIS's cancel sent to them as Ctrl-C (an ingest stops at a tile boundary and
`Resume` continues it)."""
import os
import signal
import subprocess

from qgis.core import (QgsCoordinateReferenceSystem, QgsProcessingAlgorithm,
                       QgsProcessingException, QgsProcessingParameterBoolean, QgsProcessingParameterFile,
                       QgsProcessingParameterFileDestination, QgsProcessingParameterFolderDestination,
                       QgsProcessingParameterNumber, QgsProcessingParameterPoint, QgsProcessingParameterRasterLayer)

from . import locations
from .layers import dem_path


def run_strata(arguments, feedback):
    """Runs `strata ARGUMENTS...`; its standard output goes to the log. Raises QgsProcessingException
    with the command's message when it fails or is cancelled."""
    if not os.access(locations.EXECUTABLE, os.X_OK):
        raise QgsProcessingException(f"the strata command is not at {locations.EXECUTABLE}")
    command = [locations.EXECUTABLE] + [str(a) for a in arguments]
    feedback.pushCommandInfo(" ".join(command))
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    cancelled = False
    while True:
        try:
            out, err = proc.communicate(timeout=0.25)
            break
        except subprocess.TimeoutExpired:
            if feedback.isCanceled() and not cancelled:
                proc.send_signal(signal.SIGINT)
                cancelled = True
    for line in out.splitlines():
        feedback.pushConsoleInfo(line)
    if cancelled:
        raise QgsProcessingException(f"cancelled: {err.strip() or 'strata stopped'}")
    if proc.returncode != 0:
        raise QgsProcessingException(err.strip() or f"strata {arguments[0]} failed (exit {proc.returncode})")
    for line in err.splitlines():  # warnings
        feedback.reportError(line, False)


class _Command(QgsProcessingAlgorithm):
    def createInstance(self):  # noqa: N802 (QGIS's names from here on)
        return type(self)()

    def group(self):
        return "Terrain"

    def groupId(self):
        return "terrain"


class IngestAlgorithm(_Command):
    def name(self):
        return "ingest"

    def displayName(self):  # noqa: N802
        return "Ingest DEM to store"

    def shortHelpString(self):  # noqa: N802
        return ("Builds a Strata terrain tile store from a DEM (strata ingest): tiles of 2^k samples a side, each the "
                "coarsest within the maximum error of every source cell, streamed by the viewer and renderer and "
                "readable by scenarios (store = ...). Peak memory is a few tiles whatever the DEM's size.")

    def initAlgorithm(self, config=None):  # noqa: N802
        self.addParameter(QgsProcessingParameterRasterLayer("DEM", "DEM (elevation, m)"))
        self.addParameter(QgsProcessingParameterNumber(
            "MAX_ERROR", "Largest vertical error (m; 0: lossless)", QgsProcessingParameterNumber.Double, 0.5, False, 0))
        self.addParameter(QgsProcessingParameterBoolean("RESUME", "Resume an interrupted ingest into the folder", False))
        self.addParameter(QgsProcessingParameterFolderDestination("OUTPUT", "Store folder"))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        dem = dem_path(self.parameterAsRasterLayer(parameters, "DEM", context))
        store = self.parameterAsString(parameters, "OUTPUT", context)
        arguments = ["ingest", store, "--dem", dem,
                     "--max-error", repr(self.parameterAsDouble(parameters, "MAX_ERROR", context))]
        if self.parameterAsBool(parameters, "RESUME", context):
            arguments.append("--resume")
        elif os.path.isdir(store) and not os.listdir(store):
            os.rmdir(store)  # an empty folder (QGIS may make it): strata ingest makes the store's own
        run_strata(arguments, feedback)
        return {"OUTPUT": store}


class RenderAlgorithm(_Command):
    def name(self):
        return "render"

    def displayName(self):  # noqa: N802
        return "Render picture"

    def shortHelpString(self):  # noqa: N802
        return ("Draws the DEM (or a tile store) offscreen with Strata's concentric-ring renderer (strata render) "
                "from a camera above a point: its height above the ground, heading (clockwise from north), pitch "
                "(negative looks down) and field of view. Writes a PNG.")

    def initAlgorithm(self, config=None):  # noqa: N802
        self.addParameter(QgsProcessingParameterRasterLayer("DEM", "DEM (elevation, m)"))
        self.addParameter(QgsProcessingParameterFile(
            "STORE", "Tile store instead of the DEM's file (optional)", QgsProcessingParameterFile.Folder,
            optional=True))
        self.addParameter(QgsProcessingParameterPoint("CAMERA", "Camera above (default: the DEM's centre)",
                                                      optional=True))
        self.addParameter(QgsProcessingParameterNumber(
            "AGL", "Camera height above the ground (m)", QgsProcessingParameterNumber.Double, 1000, False, -1e8, 1e8))
        self.addParameter(QgsProcessingParameterNumber(
            "HEADING", "Heading (degrees clockwise from north)", QgsProcessingParameterNumber.Double, 0, False,
            -3600, 3600))
        self.addParameter(QgsProcessingParameterNumber(
            "PITCH", "Pitch (degrees; negative looks down)", QgsProcessingParameterNumber.Double, -30, False, -90, 90))
        self.addParameter(QgsProcessingParameterNumber(
            "FOV", "Vertical field of view (degrees)", QgsProcessingParameterNumber.Double, 45, False, 1, 170))
        self.addParameter(QgsProcessingParameterNumber(
            "WIDTH", "Width (pixels)", QgsProcessingParameterNumber.Integer, 1280, False, 1, 16384))
        self.addParameter(QgsProcessingParameterNumber(
            "HEIGHT", "Height (pixels)", QgsProcessingParameterNumber.Integer, 720, False, 1, 16384))
        self.addParameter(QgsProcessingParameterNumber(
            "EXAGGERATION", "Vertical exaggeration", QgsProcessingParameterNumber.Double, 1, False, 1e-3, 1e3))
        self.addParameter(QgsProcessingParameterBoolean("OVERWRITE", "Replace the picture if it exists", False))
        self.addParameter(QgsProcessingParameterFileDestination("OUTPUT", "Picture", "PNG files (*.png)"))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        layer = self.parameterAsRasterLayer(parameters, "DEM", context)
        store = self.parameterAsFile(parameters, "STORE", context)
        source = store if store else dem_path(layer)
        out = self.parameterAsFileOutput(parameters, "OUTPUT", context)
        arguments = ["render", source, "-o", out,
                     "--size", f"{self.parameterAsInt(parameters, 'WIDTH', context)}x"
                               f"{self.parameterAsInt(parameters, 'HEIGHT', context)}"]
        for option, key in (("--agl", "AGL"), ("--heading", "HEADING"), ("--pitch", "PITCH"), ("--fov", "FOV"),
                            ("--exaggeration", "EXAGGERATION")):
            arguments += [option, repr(self.parameterAsDouble(parameters, key, context))]
        if parameters.get("CAMERA") is not None:
            # --lon/--lat are in the DEM's CRS (degrees on a geographic one, metres on a projected one).
            crs = layer.crs() if layer is not None else QgsCoordinateReferenceSystem()
            point = self.parameterAsPoint(parameters, "CAMERA", context, crs)
            arguments += ["--lon", repr(point.x()), "--lat", repr(point.y())]
        if self.parameterAsBool(parameters, "OVERWRITE", context):
            arguments.append("--overwrite")
        run_strata(arguments, feedback)
        return {"OUTPUT": out}
