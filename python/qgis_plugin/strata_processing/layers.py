"""QGIS layers in, Strata's scenario keys out, and a run's maps back as styled QGIS outputs: what the
Flood and Erosion algorithms share (whatif.py)."""
import math
import os
import sys

from qgis.core import (NULL, QgsCoordinateTransform, QgsGeometry, QgsProcessingContext, QgsProcessingException,
                       QgsProcessingLayerPostProcessorInterface, QgsProcessingUtils, QgsWkbTypes)

from . import locations


def import_strata():
    """The `strata` module of this plugin's Strata (the build tree's or the prefix's, see locations.py)."""
    if locations.PYTHON_DIR not in sys.path:
        sys.path.insert(0, locations.PYTHON_DIR)
    try:
        import strata
    except ImportError as e:
        raise QgsProcessingException(f"Strata's Python module is not in {locations.PYTHON_DIR}: {e}") from e
    return strata


def dem_path(layer, what="DEM"):
    """The file behind a raster layer GDAL reads (Strata reads the file itself, through GDAL)."""
    if layer is None:
        raise QgsProcessingException(f"{what}: no raster layer")
    path = layer.source().split("|")[0]
    if layer.providerType() != "gdal" or not (os.path.isfile(path) or path.startswith("/vsi")):
        raise QgsProcessingException(f"{what} '{layer.name()}': not a raster file GDAL reads ({layer.source()})")
    return path if path.startswith("/vsi") else os.path.abspath(path)


def number(value, what):
    """A finite float from an attribute or a matrix cell, else a one-line error naming it."""
    if value is None or value == NULL:
        raise QgsProcessingException(f"{what}: no value")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise QgsProcessingException(f"{what}: '{value}' is not a number") from None
    if not math.isfinite(v):
        raise QgsProcessingException(f"{what}: {v} is not a finite number")
    return v


class Feature:
    """One feature of a layer in the DEM's CRS: its scenario geometry key and value, its attributes."""

    def __init__(self, label, key, coords, attributes):
        self.label = label  # "layer 'name', feature 3" for messages
        self.key = key  # at_xy, line_xy or polygon_xy
        self.coords = coords
        self.attributes = attributes

    def value(self, field, what):
        return number(self.attributes.get(field), f"{self.label}: {what} (field '{field}')")


def features(source, layer_name, dem_crs, context, kinds):
    """Every feature of `source` (a QgsProcessingFeatureSource or None) reprojected to `dem_crs`, as
    Feature objects. kinds: the geometry types allowed ("point", "line", "polygon"). A feature of
    several parts is refused (each inflow, level or gauge is one place: a multi-line inflow would
    pour its discharge in each part)."""
    if source is None:
        return []
    crs = source.sourceCrs()
    transform = QgsCoordinateTransform(crs, dem_crs, context.transformContext()) if crs.isValid() else None
    names = {QgsWkbTypes.PointGeometry: "point", QgsWkbTypes.LineGeometry: "line",
             QgsWkbTypes.PolygonGeometry: "polygon"}
    out = []
    for f in source.getFeatures():
        label = f"layer '{layer_name}', feature {f.id()}"
        g = QgsGeometry(f.geometry())
        if g.isNull() or g.isEmpty():
            raise QgsProcessingException(f"{label}: no geometry")
        if transform is not None and g.transform(transform) != 0:
            raise QgsProcessingException(f"{label}: cannot be transformed to the DEM's CRS {dem_crs.authid()}")
        kind = names.get(QgsWkbTypes.geometryType(g.wkbType()))
        if kind not in kinds:
            raise QgsProcessingException(f"{label}: a {kind or 'geometry'}; expected a {' or '.join(kinds)}")
        parts = g.asGeometryCollection() if g.isMultipart() else [g]
        if len(parts) != 1:
            raise QgsProcessingException(f"{label}: {len(parts)} parts; give one {kind} per feature")
        part = parts[0]
        if kind == "point":
            p = part.asPoint()
            key, coords = "at_xy", [p.x(), p.y()]
        elif kind == "line":
            key, coords = "line_xy", [[p.x(), p.y()] for p in part.asPolyline()]
        else:
            ring = part.asPolygon()[0]
            if len(ring) > 1 and ring[0] == ring[-1]:
                ring = ring[:-1]  # the scenario's polygons are open rings
            key, coords = "polygon_xy", [[p.x(), p.y()] for p in ring]
        attributes = {field.name(): f[field.name()] for field in f.fields()}
        out.append(Feature(label, key, coords, attributes))
    return out


def feature_name(feature, field, fallback):
    if field and feature.attributes.get(field) not in (None, NULL, ""):
        return str(feature.attributes[field])
    name = feature.attributes.get("name")
    return str(name) if name not in (None, NULL, "") else fallback


class _LoadStyle(QgsProcessingLayerPostProcessorInterface):
    """Applies the .qml style Strata wrote beside a map when QGIS loads the output layer."""

    def __init__(self, qml):
        super().__init__()
        self.qml = qml

    def postProcessLayer(self, layer, context, feedback):  # noqa: N802 (QGIS's name)
        message, ok = layer.loadNamedStyle(self.qml)
        if not ok:
            feedback.reportError(f"{self.qml}: style not applied ({message})", False)
        layer.triggerRepaint()


# QGIS keeps a pointer to each post-processor, not a reference: they live as long as the plugin.
_post_processors = []


def add_styled_output(context, source, qml, name, output, hint):
    """Asks QGIS to load `source` when the algorithm finishes, styled with `qml`."""
    details = QgsProcessingContext.LayerDetails(name, context.project(), output, hint)
    style = _LoadStyle(qml)
    _post_processors.append(style)
    details.setPostProcessor(style)
    context.addLayerToLoadOnCompletion(source, details)


def map_outputs(folder, outputs, context, prefix):
    """The run's maps named in `outputs` ({output name: map name}) that it wrote: results for the
    algorithm ({output name: layer source}), each loaded on completion with its style."""
    results = {}
    for output, name in outputs.items():
        if name == "flood_outline":
            path = os.path.join(folder, "maps", "flood_outline.gpkg")
            source, hint = f"{path}|layername=flood_outline", QgsProcessingUtils.LayerHint.Vector
        else:
            path = os.path.join(folder, "maps", name + ".tif")
            source, hint = path, QgsProcessingUtils.LayerHint.Raster
        if not os.path.isfile(path):
            continue
        qml = os.path.join(folder, "maps", name + ".qml")
        add_styled_output(context, source, qml, f"{prefix} {name.replace('_', ' ')}", output, hint)
        results[output] = source
    return results
