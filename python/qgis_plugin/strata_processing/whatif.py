"""Flood what-if and Erosion what-if: a scenario built from the dialog's layers and numbers, run by
Strata's Python module (strata.run: the command line's checks, solver and outputs), its maps
returned as layers that load with Strata's styles. The run writes the scenario to its folder as
scenario.toml: `strata flood FOLDER/scenario.toml` runs the same what-if from a shell."""
import os

from qgis.core import (QgsProcessing, QgsProcessingAlgorithm, QgsProcessingException, QgsProcessingOutputFile,
                       QgsProcessingOutputRasterLayer, QgsProcessingOutputVectorLayer, QgsProcessingParameterBoolean,
                       QgsProcessingParameterDefinition, QgsProcessingParameterEnum, QgsProcessingParameterExtent,
                       QgsProcessingParameterFeatureSource, QgsProcessingParameterField,
                       QgsProcessingParameterFolderDestination, QgsProcessingParameterMatrix,
                       QgsProcessingParameterNumber, QgsProcessingParameterRasterLayer)

from .layers import dem_path, feature_name, features, import_strata, map_outputs, number

BACKENDS = ["cpu", "gpu", "auto"]
EDGES = ["west", "east", "south", "north"]
LAWS = ["shear", "force-based"]


def _advanced(param):
    param.setFlags(param.flags() | QgsProcessingParameterDefinition.FlagAdvanced)
    return param


class _WhatIf(QgsProcessingAlgorithm):
    """What both what-ifs take (a DEM, a region, inflows, roughness, time, the run folder) and do
    (build the scenario, run it with progress and cancel, return the maps)."""

    maps = {}  # output name -> map name, per algorithm

    def createInstance(self):  # noqa: N802 (QGIS's names from here on)
        return type(self)()

    def group(self):
        return "What-ifs"

    def groupId(self):
        return "whatif"

    def addTerrainParameters(self, manning_n):
        self.addParameter(QgsProcessingParameterRasterLayer("DEM", "DEM (elevation, m)"))
        self.addParameter(QgsProcessingParameterExtent("EXTENT", "Region (default: the whole DEM)", optional=True))
        self.addParameter(QgsProcessingParameterNumber(
            "CELL_SIZE", "Cell size (m; 0: the DEM's own cells)", QgsProcessingParameterNumber.Double, 0, False, 0))
        self.addParameter(QgsProcessingParameterNumber(
            "MANNING", "Manning's n (s/m^(1/3))", QgsProcessingParameterNumber.Double, manning_n, False, 0.001, 1))
        self.addParameter(QgsProcessingParameterRasterLayer(
            "MANNING_RASTER", "Manning's n per cell (optional raster)", optional=True))

    def addInflowParameters(self):
        self.addParameter(QgsProcessingParameterFeatureSource(
            "INFLOWS", "Inflows (lines across a river, or points)",
            [QgsProcessing.TypeVectorLine, QgsProcessing.TypeVectorPoint], optional=True))
        self.addParameter(QgsProcessingParameterField(
            "INFLOW_PEAK_FIELD", "Peak discharge field (m3/s; default: the number below)", None, "INFLOWS",
            QgsProcessingParameterField.Numeric, optional=True))
        self.addParameter(QgsProcessingParameterNumber(
            "PEAK", "Peak discharge of each inflow (m3/s)", QgsProcessingParameterNumber.Double, 1000, False, 0))
        self.addParameter(QgsProcessingParameterMatrix(
            "HYDROGRAPH", "Hydrograph (time in hours, fraction of the peak)", numberRows=4, hasFixedNumberRows=False,
            headers=["Time (h)", "Fraction of peak"], defaultValue=[0, 0, 0.5, 1, 2, 1, 2.5, 0],
            optional=True))  # optional: QGIS 3.22 then takes the default when none is given

    def addRunParameters(self, duration_h):
        self.addParameter(QgsProcessingParameterNumber(
            "DURATION", "Duration (h)", QgsProcessingParameterNumber.Double, duration_h, False, 1e-3, 1e5))
        self.addParameter(_advanced(QgsProcessingParameterNumber(
            "OUTPUT_INTERVAL", "Output interval (min; 0: a tenth of the duration)",
            QgsProcessingParameterNumber.Double, 0, False, 0)))
        self.addParameter(QgsProcessingParameterEnum(
            "CLOSED_EDGES", "Closed edges of the region (walls; water leaves through the others)", EDGES,
            allowMultiple=True, optional=True))
        self.addParameter(_advanced(QgsProcessingParameterBoolean(
            "FILL_DEPRESSIONS", "Fill pits to their spill level", False)))
        self.addParameter(_advanced(QgsProcessingParameterBoolean(
            "BREACH_INFLOWS", "Carve each inflow's path to an open edge", False)))
        self.addParameter(_advanced(QgsProcessingParameterEnum(
            "BACKEND", "Backend (gpu: GL compute shaders)", BACKENDS, defaultValue=2)))
        self.addParameter(_advanced(QgsProcessingParameterBoolean("PLOTS", "Plots in the report", True)))
        self.addParameter(_advanced(QgsProcessingParameterBoolean(
            "RESUME", "Resume the stopped run in the folder", False)))
        self.addParameter(_advanced(QgsProcessingParameterBoolean(
            "OVERWRITE", "Replace an earlier run in the folder", False)))
        self.addParameter(QgsProcessingParameterFolderDestination("OUTPUT", "Run folder"))
        for output, name in self.maps.items():
            title = name.replace("_", " ").capitalize()
            self.addOutput(QgsProcessingOutputVectorLayer(output, title) if name == "flood_outline"
                           else QgsProcessingOutputRasterLayer(output, title))
        self.addOutput(QgsProcessingOutputFile("REPORT", "Report (Markdown)"))
        self.addOutput(QgsProcessingOutputFile("SCENARIO", "Scenario (TOML, for `strata flood`)"))

    def layerName(self, parameters, key, context):
        """The name of the layer behind a vector parameter, for messages."""
        layer = self.parameterAsVectorLayer(parameters, key, context)
        return layer.name() if layer is not None else key.lower()

    # --- the scenario -------------------------------------------------------------------------------

    def baseScenario(self, parameters, context, dem):
        """[terrain], [region], [model] and [time] from the common parameters."""
        closed = set(self.parameterAsEnums(parameters, "CLOSED_EDGES", context))
        d = {"name": self.displayName(),
             "terrain": {"dem": dem_path(dem)},
             "model": {"kind": "flood",
                       "manning_n": self.parameterAsDouble(parameters, "MANNING", context),
                       "boundary": {edge: "closed" if i in closed else "open" for i, edge in enumerate(EDGES)}},
             "time": {"duration": f"{self.parameterAsDouble(parameters, 'DURATION', context)!r} h"},
             "water": {}, "outputs": {}}
        if self.parameterAsBool(parameters, "FILL_DEPRESSIONS", context):
            d["terrain"]["fill_depressions"] = True
        if self.parameterAsBool(parameters, "BREACH_INFLOWS", context):
            d["terrain"]["breach_inflows"] = True
        interval = self.parameterAsDouble(parameters, "OUTPUT_INTERVAL", context)
        if interval > 0:
            d["time"]["output_interval"] = f"{interval!r} min"
        region = {}
        if parameters.get("EXTENT") is not None:
            extent = self.parameterAsExtent(parameters, "EXTENT", context, dem.crs())
            if not extent.isNull() and not extent.isEmpty():
                region["bbox_xy"] = [extent.xMinimum(), extent.yMinimum(), extent.xMaximum(), extent.yMaximum()]
        cell = self.parameterAsDouble(parameters, "CELL_SIZE", context)
        if cell > 0:
            region["cell_size"] = f"{cell!r} m"
        if region:
            d["region"] = region
        manning = self.parameterAsRasterLayer(parameters, "MANNING_RASTER", context)
        if manning is not None:
            d["model"]["manning_raster"] = dem_path(manning, "Manning's n raster")
        return d

    def addInflows(self, d, parameters, context, dem):
        source = self.parameterAsSource(parameters, "INFLOWS", context)
        if source is None:
            return
        field = self.parameterAsString(parameters, "INFLOW_PEAK_FIELD", context)
        default_peak = self.parameterAsDouble(parameters, "PEAK", context)
        matrix = self.parameterAsMatrix(parameters, "HYDROGRAPH", context)
        if len(matrix) < 2 or len(matrix) % 2:
            raise QgsProcessingException("Hydrograph: give rows of two numbers (time in hours, fraction of the peak)")
        shape = [(number(matrix[i], f"Hydrograph row {i // 2 + 1}: time"),
                  number(matrix[i + 1], f"Hydrograph row {i // 2 + 1}: fraction")) for i in range(0, len(matrix), 2)]
        inflows = []
        for i, f in enumerate(features(source, self.layerName(parameters, "INFLOWS", context), dem.crs(), context,
                                       ["line", "point"])):
            peak = f.value(field, "peak discharge") if field else default_peak
            inflows.append({"name": feature_name(f, None, f"inflow {i + 1}"), f.key: f.coords,
                            "hydrograph": [[t, frac * peak] for t, frac in shape], "hydrograph_units": ["h", "m3/s"]})
        if inflows:
            d["water"]["inflow"] = inflows

    def runScenario(self, d, parameters, context, feedback):
        """Checks and runs the scenario `d` into the OUTPUT folder; returns the algorithm's results."""
        strata = import_strata()
        folder = self.parameterAsString(parameters, "OUTPUT", context)
        os.makedirs(folder, exist_ok=True)
        if not d["water"]:
            del d["water"]
        scenario_file = os.path.join(folder, "scenario.toml")  # the run writes it, as `strata flood` does
        try:
            scenario = strata.scenario_from_dict(d, folder, "scenario.toml")
        except strata.ScenarioError as e:
            raise QgsProcessingException(str(e)) from None
        feedback.pushInfo(f"{scenario.name}: {scenario.duration_s:.0f} s into {folder}")

        def progress(t, total):
            if total > 0:
                feedback.setProgress(100.0 * t / total)
            return not feedback.isCanceled()

        def log(level, category, message):  # the lines `strata flood` prints, in the algorithm's log
            if level == "warning":
                feedback.pushWarning(f"{category}: {message}")
            elif level == "error":
                feedback.reportError(f"{category}: {message}", False)
            elif category == "progress":
                feedback.pushDebugInfo(message)
            else:
                feedback.pushInfo(f"{category}: {message}")

        try:
            run = strata.run(scenario, folder, backend=BACKENDS[self.parameterAsEnum(parameters, "BACKEND", context)],
                             plots=self.parameterAsBool(parameters, "PLOTS", context),
                             resume=self.parameterAsBool(parameters, "RESUME", context),
                             overwrite=self.parameterAsBool(parameters, "OVERWRITE", context), progress=progress,
                             log=log)
        except strata.Cancelled as e:
            raise QgsProcessingException(f"{e}; run again with 'Resume the stopped run in the folder' to continue "
                                         f"from {folder}") from None
        except (strata.ScenarioError, RuntimeError, ValueError) as e:
            raise QgsProcessingException(str(e)) from None
        feedback.pushInfo(f"{run!r}: {run.steps} steps in {run.wall_s:.1f} s")
        results = {"OUTPUT": folder, "REPORT": os.path.join(folder, "report.md"), "SCENARIO": scenario_file}
        results.update(map_outputs(folder, self.maps, context, self.displayName() + ":"))
        return results


class FloodAlgorithm(_WhatIf):
    maps = {"MAX_DEPTH": "max_depth", "MAX_SPEED": "max_speed", "ARRIVAL_TIME": "arrival_time",
                   "HAZARD_RATING": "hazard_rating", "FLOOD_OUTLINE": "flood_outline"}

    def name(self):
        return "flood"

    def displayName(self):  # noqa: N802
        return "Flood what-if"

    def shortHelpString(self):  # noqa: N802
        return ("Floods a DEM with shallow water (finite volumes, Manning friction): inflows from a line or point "
                "layer with a hydrograph, rain, fixed water levels (lines or polygons with a water surface "
                "elevation), dam breaks (polygons of standing water released at t = 0) and gauges (points: "
                "gauges.csv). Returns the maximum depth, maximum speed, arrival time, hazard rating and flood "
                "outline, styled, in the DEM's CRS; the run folder holds report.md, series.csv and scenario.toml. "
                "Cancel stops at the next step and leaves a folder that 'Resume' continues.")

    def initAlgorithm(self, config=None):  # noqa: N802
        self.addTerrainParameters(manning_n=0.035)
        self.addInflowParameters()
        self.addParameter(QgsProcessingParameterNumber(
            "RAIN", "Rain (mm/h, the whole run)", QgsProcessingParameterNumber.Double, 0, False, 0, 1000))
        self.addParameter(QgsProcessingParameterNumber(
            "INFILTRATION", "Infiltration loss (mm/h)", QgsProcessingParameterNumber.Double, 0, False, 0, 1000))
        self.addParameter(QgsProcessingParameterFeatureSource(
            "LEVELS", "Fixed water levels (lines or polygons)",
            [QgsProcessing.TypeVectorLine, QgsProcessing.TypeVectorPolygon], optional=True))
        self.addParameter(QgsProcessingParameterField(
            "LEVEL_FIELD", "Water surface elevation field of the levels (m)", None, "LEVELS",
            QgsProcessingParameterField.Numeric, optional=True))
        self.addParameter(QgsProcessingParameterFeatureSource(
            "DAM_BREAKS", "Dam breaks (polygons of standing water)", [QgsProcessing.TypeVectorPolygon], optional=True))
        self.addParameter(QgsProcessingParameterField(
            "DAM_SURFACE_FIELD", "Water surface elevation field of the dam breaks (m)", None, "DAM_BREAKS",
            QgsProcessingParameterField.Numeric, optional=True))
        self.addParameter(QgsProcessingParameterFeatureSource(
            "GAUGES", "Gauges (points)", [QgsProcessing.TypeVectorPoint], optional=True))
        self.addParameter(QgsProcessingParameterField(
            "GAUGE_NAME_FIELD", "Gauge name field", None, "GAUGES", optional=True))
        self.addParameter(QgsProcessingParameterNumber(
            "WET_THRESHOLD", "Flooded above (m)", QgsProcessingParameterNumber.Double, 0.1, False, 0))
        self.addRunParameters(duration_h=3)
        self.addOutput(QgsProcessingOutputFile("GAUGES_CSV", "Gauge series (CSV)"))

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        dem = self.parameterAsRasterLayer(parameters, "DEM", context)
        d = self.baseScenario(parameters, context, dem)
        self.addInflows(d, parameters, context, dem)
        rain = self.parameterAsDouble(parameters, "RAIN", context)
        if rain > 0:
            d["water"]["rain"] = {"rate": f"{rain!r} mm/h"}
        loss = self.parameterAsDouble(parameters, "INFILTRATION", context)
        if loss > 0:
            d["water"]["infiltration"] = {"model": "constant", "rate": f"{loss!r} mm/h"}
        duration_s = 3600.0 * self.parameterAsDouble(parameters, "DURATION", context)
        for kind, field_param, what, kinds in (("LEVELS", "LEVEL_FIELD", "level", ["line", "polygon"]),
                                               ("DAM_BREAKS", "DAM_SURFACE_FIELD", "dam break", ["polygon"])):
            source = self.parameterAsSource(parameters, kind, context)
            if source is None:
                continue
            field = self.parameterAsString(parameters, field_param, context)
            if not field:
                raise QgsProcessingException(f"{what.capitalize()}s given: name the field with their water surface "
                                             f"elevation ({field_param})")
            entries = []
            for i, f in enumerate(features(source, self.layerName(parameters, kind, context), dem.crs(), context,
                                           kinds)):
                z = f.value(field, "water surface elevation")
                if kind == "LEVELS":
                    entries.append({"name": feature_name(f, None, f"level {i + 1}"), f.key: f.coords,
                                    "stage": [[0, z], [duration_s, z]]})
                else:
                    entries.append({f.key: f.coords, "surface": f"{z!r} m"})
            if entries:
                d["water"]["level" if kind == "LEVELS" else "dam_break"] = entries
        gauges = self.parameterAsSource(parameters, "GAUGES", context)
        name_field = self.parameterAsString(parameters, "GAUGE_NAME_FIELD", context)
        gauge_list = [{"name": feature_name(f, name_field, f"gauge {i + 1}"), "at_xy": f.coords}
                      for i, f in enumerate(features(gauges, self.layerName(parameters, "GAUGES", context), dem.crs(),
                                                     context, ["point"]))]
        if gauge_list:
            d["outputs"]["gauge"] = gauge_list
        d["outputs"]["maps"] = ["max_depth", "max_speed", "arrival_time", "inundation_duration", "final_depth",
                                "hazard_rating", "flood_outline"]
        d["outputs"]["wet_threshold"] = f"{self.parameterAsDouble(parameters, 'WET_THRESHOLD', context)!r} m"
        results = self.runScenario(d, parameters, context, feedback)
        gauges_csv = os.path.join(results["OUTPUT"], "gauges.csv")
        if os.path.isfile(gauges_csv):
            results["GAUGES_CSV"] = gauges_csv
        return results


class ErosionAlgorithm(_WhatIf):
    maps = {"TERRAIN_CHANGE": "terrain_change", "EXPOSED_MATERIAL": "exposed_material",
                   "MAX_DEPTH": "max_depth", "SUSPENDED_SEDIMENT": "suspended_sediment"}

    def name(self):
        return "erosion"

    def displayName(self):  # noqa: N802
        return "Erosion what-if"

    def shortHelpString(self):  # noqa: N802
        return ("Rain (and optional inflows) eroding layered ground: material layers from the bottom up (rock, "
                "soil, sand, sediment, each with a thickness), entrained by the bed shear stress and settling at "
                "the grains' velocity (the 'shear' law) or the force-based authoring law, with slope weathering "
                "and bank failure when 'thermal' is on. Returns the terrain change (cut < 0 < fill), the exposed "
                "material, the maximum depth and the suspended sediment, styled, in the DEM's CRS; report.md "
                "holds the material balance.")

    def initAlgorithm(self, config=None):  # noqa: N802
        self.addTerrainParameters(manning_n=0.05)
        self.addParameter(QgsProcessingParameterMatrix(
            "LAYERS", "Material layers, bottom first (material: rock, soil, sand or sediment; thickness in m)",
            numberRows=4, hasFixedNumberRows=False, headers=["Material", "Thickness (m)"],
            defaultValue=["rock", 20, "soil", 3, "sand", 1, "sediment", 0], optional=True))
        self.addParameter(QgsProcessingParameterNumber(
            "RAIN", "Rain (mm/h)", QgsProcessingParameterNumber.Double, 40, False, 0, 1000))
        self.addParameter(QgsProcessingParameterNumber(
            "RAIN_HOURS", "Rain lasts (h)", QgsProcessingParameterNumber.Double, 3, False, 0))
        self.addInflowParameters()
        self.addParameter(QgsProcessingParameterEnum("LAW", "Erosion law", LAWS, defaultValue=0))
        self.addParameter(QgsProcessingParameterBoolean("THERMAL", "Slope weathering and bank failure", True))
        self.addRunParameters(duration_h=6)

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        dem = self.parameterAsRasterLayer(parameters, "DEM", context)
        d = self.baseScenario(parameters, context, dem)
        d["terrain"]["voids"] = "fill"
        matrix = self.parameterAsMatrix(parameters, "LAYERS", context)
        if not matrix or len(matrix) % 2:
            raise QgsProcessingException("Material layers: give rows of a material and a thickness in metres")
        d["terrain"]["layer"] = [{"material": str(matrix[i]).strip(),
                                  "thickness": f"{number(matrix[i + 1], f'Material layer {i // 2 + 1}: thickness')!r} m",
                                  "at_rest": True} for i in range(0, len(matrix), 2)]
        rain, hours = (self.parameterAsDouble(parameters, k, context) for k in ("RAIN", "RAIN_HOURS"))
        if rain > 0 and hours > 0:
            d["water"]["rain"] = {"rate": f"{rain!r} mm/h", "start": "0 h", "end": f"{hours!r} h"}
        self.addInflows(d, parameters, context, dem)
        d["erosion"] = {"enabled": True, "law": LAWS[self.parameterAsEnum(parameters, "LAW", context)],
                        "thermal": self.parameterAsBool(parameters, "THERMAL", context)}
        d["outputs"]["wet_threshold"] = "0.05 m"
        return self.runScenario(d, parameters, context, feedback)
