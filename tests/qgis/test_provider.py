#!/usr/bin/python3
"""The QGIS plugin's Processing provider in headless QGIS (issue 32; docs/qgis.md), as a user's
processing.run would use it:
- Flood what-if on the Grand Canyon DEM layer with an inflow line layer and a gauge point layer
  made here gives output layers that are valid, in the DEM's CRS, styled as QGIS loads them (the
  post-processors QGIS runs on completion), and equal bit for bit to `strata flood` on the same
  scenario written by hand (max depth, max speed, arrival time, hazard, the outline's area, the
  gauge's series);
- an inflow layer in another CRS (Web Mercator) reaches the scenario in the DEM's CRS; a cancelled
  run raises, leaves a resumable folder, and RESUME finishes it; a bad field value is refused
  naming the layer, the feature and the field; a dam-break polygon layer and a level line layer
  reach the scenario with their fields' elevations; a Manning raster layer sets n;
- Erosion what-if on Mount Rainier gives a styled terrain change with cut and fill;
- Ingest DEM to store writes a store, and Render picture draws it to a PNG that is not blank;
- the Flood algorithm runs as a child of a Processing model (the graphical modeller's form).

    test_provider.py STRATA_CLI SOURCE_DIR PLUGIN_PARENT_DIR WORK_DIR
"""
import math
import os
import shutil
import subprocess
import sys
import tomllib

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
# QGIS computes a DEM layer's statistics for its default style, and GDAL would keep them in a
# .aux.xml beside the shared DEMs (where gdaldem, in another test, would then read them).
os.environ["GDAL_PAM_ENABLED"] = "NO"

import numpy as np  # noqa: E402
from osgeo import gdal  # noqa: E402
from qgis.core import (QgsApplication, QgsFeature, QgsGeometry, QgsPointXY, QgsProcessingContext,  # noqa: E402
                       QgsProcessingException, QgsProcessingFeedback, QgsProcessingModelAlgorithm,
                       QgsProcessingModelChildAlgorithm, QgsProcessingModelChildParameterSource,
                       QgsProcessingModelOutput, QgsProcessingModelParameter, QgsProcessingParameterRasterLayer,
                       QgsProcessingUtils, QgsProject, QgsRasterLayer, QgsVectorLayer)

gdal.UseExceptions()


def check(cond, what):
    if not cond:
        sys.exit("FAILED: " + what)
    print("ok:", what)


def values(path):
    return gdal.Open(path).ReadAsArray().astype(np.float64)


def same(a, b):
    return a.shape == b.shape and np.array_equal(a, b, equal_nan=True)


def memory_layer(uri, name, geometries, attributes):
    layer = QgsVectorLayer(uri, name, "memory")
    features = []
    for geometry, attrs in zip(geometries, attributes):
        f = QgsFeature(layer.fields())
        f.setGeometry(geometry)
        f.setAttributes(attrs)
        features.append(f)
    layer.dataProvider().addFeatures(features)
    return layer


class Recorder(QgsProcessingFeedback):
    def __init__(self):
        super().__init__()
        self.warnings = []

    def pushWarning(self, warning):  # noqa: N802 (QGIS's name)
        super().pushWarning(warning)
        self.warnings.append(warning)


class CancelAfterFirstInterval(QgsProcessingFeedback):
    def setProgress(self, progress):  # noqa: N802 (QGIS's name)
        super().setProgress(progress)
        if progress >= 30:
            self.cancel()


def loaded_layers(context, feedback):
    """What QGIS does on completion: each output layer loaded from its source and post-processed."""
    layers = {}
    for source, details in context.layersToLoadOnCompletion().items():
        layer = QgsProcessingUtils.mapLayerFromString(source, context)
        check(layer is not None and layer.isValid(), f"output {details.outputName} loads: {source}")
        details.postProcessor().postProcessLayer(layer, context, feedback)
        layers[details.outputName] = layer
    return layers


def main():
    cli, source, plugin_parent, work = (os.path.abspath(a) for a in sys.argv[1:5])
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    app = QgsApplication([], False)
    app.initQgis()
    sys.path.append(os.path.join(QgsApplication.pkgDataPath(), "python", "plugins"))  # Processing itself
    import processing
    from processing.core.Processing import Processing
    Processing.initialize()
    sys.path.insert(0, plugin_parent)
    import strata_processing
    plugin = strata_processing.classFactory(None)
    plugin.initProcessing()
    registry = QgsApplication.processingRegistry()
    ids = sorted(a.id() for a in registry.providerById("strata").algorithms())
    check(ids == ["strata:erosion", "strata:flood", "strata:ingest", "strata:render"], f"the provider's algorithms {ids}")

    data = os.path.normpath(os.path.join(source, "..", "shared", "data"))
    dem_file = os.path.join(data, "grand_canyon", "grand_canyon_512.tif")
    dem = QgsRasterLayer(dem_file, "grand canyon")
    check(dem.isValid() and dem.crs().authid() == "EPSG:4326", "the DEM layer")
    line = [QgsPointXY(-112.0225, 36.063), QgsPointXY(-112.0225, 36.08)]
    inflows = memory_layer("LineString?crs=EPSG:4326&field=name:string&field=peak:double", "inflows",
                           [QgsGeometry.fromPolylineXY(line)], [["Colorado", 20000.0]])
    gauges = memory_layer("Point?crs=EPSG:4326&field=label:string", "gauges",
                          [QgsGeometry.fromPointXY(QgsPointXY(-112.1, 36.1))], [["canyon"]])
    bbox = [-112.25, 36.02, -112.001, 36.18]
    params = {"DEM": dem, "EXTENT": f"{bbox[0]},{bbox[2]},{bbox[1]},{bbox[3]} [EPSG:4326]", "CELL_SIZE": 600,
              "INFLOWS": inflows, "INFLOW_PEAK_FIELD": "peak", "HYDROGRAPH": [0, 0, 0.125, 1, 1, 1],
              "GAUGES": gauges, "GAUGE_NAME_FIELD": "label", "MANNING": 0.04, "CLOSED_EDGES": [1], "DURATION": 0.25,
              "OUTPUT_INTERVAL": 5, "BACKEND": 0, "PLOTS": False, "OUTPUT": os.path.join(work, "qgis")}
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    feedback = Recorder()
    results = processing.run("strata:flood", params, context=context, feedback=feedback)
    check(any("closed depressions" in w for w in feedback.warnings),
          f"the run's warnings reach the algorithm's log ({len(feedback.warnings)})")

    # The same scenario by hand, run by the command line.
    toml = os.path.join(work, "cli.toml")
    with open(toml, "w") as f:
        f.write(f"""name = "Flood what-if"
[terrain]
dem = "{dem_file}"
[region]
bbox_xy = {bbox}
cell_size = "600.0 m"
[model]
kind = "flood"
manning_n = 0.04
boundary = {{ west = "open", east = "closed", south = "open", north = "open" }}
[[water.inflow]]
name = "Colorado"
line_xy = [[-112.0225, 36.063], [-112.0225, 36.08]]
hydrograph = [[0, 0], [0.125, 20000], [1, 20000]]
hydrograph_units = ["h", "m3/s"]
[time]
duration = "0.25 h"
output_interval = "5 min"
[outputs]
maps = ["max_depth", "max_speed", "arrival_time", "inundation_duration", "final_depth", "hazard_rating",
        "flood_outline"]
wet_threshold = "0.1 m"
[[outputs.gauge]]
name = "canyon"
at_xy = [-112.1, 36.1]
""")
    cli_run = os.path.join(work, "cli")
    subprocess.run([cli, "flood", toml, "-o", cli_run, "--backend", "cpu", "--no-pictures", "--no-plots"],
                   check=True, stdout=subprocess.DEVNULL)

    layers = loaded_layers(context, feedback)
    check(sorted(layers) == ["ARRIVAL_TIME", "FLOOD_OUTLINE", "HAZARD_RATING", "MAX_DEPTH", "MAX_SPEED"],
          f"five output layers load on completion ({sorted(layers)})")
    for output, layer in layers.items():
        check(layer.crs() == dem.crs(), f"{output} is in the DEM's CRS ({layer.crs().authid()})")
        if output == "FLOOD_OUTLINE":
            renderer = layer.renderer().type()
            check(renderer == "singleSymbol" and layer.renderer().symbol().color().alpha() < 255,
                  f"{output}: styled ({renderer}, translucent fill)")
            area = sum(f["area_m2"] for f in layer.getFeatures())
            theirs = QgsVectorLayer(os.path.join(cli_run, "maps", "flood_outline.gpkg") + "|layername=flood_outline")
            check(area > 0 and area == sum(f["area_m2"] for f in theirs.getFeatures()),
                  f"{output}: {area / 1e6:.2f} km2, as the command line's")
            continue
        renderer = layer.renderer()
        items = renderer.shader().rasterShaderFunction().colorRampItemList() if renderer.type() == \
            "singlebandpseudocolor" else []
        check(len(items) >= 4, f"{output}: styled ({renderer.type()}, {len(items)} ramp items)")
        name = os.path.basename(layer.source())
        mine, theirs = values(layer.source()), values(os.path.join(cli_run, "maps", name))
        check(same(mine, theirs), f"{output}: {name} equals the command line's bit for bit")
    depth = values(results["MAX_DEPTH"])
    check(np.nanmax(depth) > 1.0, f"the canyon floods ({np.nanmax(depth):.1f} m deep at most)")
    with open(results["GAUGES_CSV"]) as a, open(os.path.join(cli_run, "gauges.csv")) as b:
        check(a.read() == b.read(), "gauges.csv (the gauge named from the layer's field) equals the command line's")
    with open(results["SCENARIO"], "rb") as f:
        check(tomllib.load(f)["water"]["inflow"][0]["name"] == "Colorado", "the run folder's scenario.toml")

    # A Manning raster layer (n = 0.04 everywhere, written here) under a MANNING of 0.2: the map's
    # n holds wherever it has data, so the answer is the first run's.
    n_file = os.path.join(work, "manning.tif")
    n_ds = gdal.GetDriverByName("GTiff").Create(n_file, 64, 48, 1, gdal.GDT_Float32)
    n_ds.SetGeoTransform([-112.3, 0.005, 0, 36.2, 0, -0.005])
    n_ds.SetProjection(dem.crs().toWkt())
    n_ds.GetRasterBand(1).Fill(0.04)
    n_ds = None
    manning = QgsRasterLayer(n_file, "manning")
    results_n = processing.run("strata:flood", dict(params, MANNING=0.2, MANNING_RASTER=manning,
                                                    OUTPUT=os.path.join(work, "manning")),
                               context=QgsProcessingContext(), feedback=QgsProcessingFeedback())
    check(same(values(results_n["MAX_DEPTH"]), depth), "a Manning raster layer of 0.04 gives the 0.04 run's depths")

    # The inflow in Web Mercator reaches the scenario in the DEM's CRS; cancel, then resume.
    def web_mercator(p):  # EPSG:3857 on the sphere of radius 6378137 m
        return QgsPointXY(6378137 * math.radians(p.x()), 6378137 * math.log(math.tan(math.pi / 4 + math.radians(p.y()) / 2)))
    mercator = memory_layer("LineString?crs=EPSG:3857&field=name:string", "inflows 3857",
                            [QgsGeometry.fromPolylineXY([web_mercator(p) for p in line])], [["Colorado"]])
    params_c = dict(params, INFLOWS=mercator, INFLOW_PEAK_FIELD=None, PEAK=20000, GAUGES=None,
                    OUTPUT=os.path.join(work, "cancelled"))
    try:
        processing.run("strata:flood", params_c, context=QgsProcessingContext(), feedback=CancelAfterFirstInterval())
        check(False, "a cancelled run raises")
    except QgsProcessingException as e:
        check(True, f"a cancelled run raises: {str(e).splitlines()[0][:100]}")
    check(os.path.isfile(os.path.join(work, "cancelled", "checkpoint.bin")), "the cancelled run left a checkpoint")
    with open(os.path.join(work, "cancelled", "scenario.toml"), "rb") as f:
        xy = tomllib.load(f)["water"]["inflow"][0]["line_xy"]
    err = max(abs(xy[0][0] + 112.0225), abs(xy[0][1] - 36.063), abs(xy[1][1] - 36.08))
    check(err < 1e-6, f"the Web Mercator line reached the scenario in degrees (off by {err:.1e} deg)")
    resumed = processing.run("strata:flood", dict(params_c, RESUME=True), context=QgsProcessingContext(),
                             feedback=QgsProcessingFeedback())
    with open(os.path.join(work, "cancelled", "series.csv")) as f:
        rows = f.read().splitlines()
    check(len(rows) == 4 and rows[-1].startswith("900") and os.path.isfile(resumed["MAX_DEPTH"]),
          f"RESUME finished the cancelled run ({len(rows) - 1} intervals)")

    bad = memory_layer("LineString?crs=EPSG:4326&field=peak:string", "bad inflows",
                       [QgsGeometry.fromPolylineXY(line)], [["lots"]])
    try:
        processing.run("strata:flood", dict(params, INFLOWS=bad, OUTPUT=os.path.join(work, "bad")),
                       context=QgsProcessingContext(), feedback=QgsProcessingFeedback())
        check(False, "a bad discharge is refused")
    except QgsProcessingException as e:
        message = str(e)
        check("bad inflows" in message and "feature" in message and "'peak'" in message,
              f"a bad discharge is refused: {message.splitlines()[0]}")
    check(not os.path.exists(os.path.join(work, "bad", "maps")), "...and nothing ran")

    # A dam break (a polygon of water standing at 900 m, closed ring in QGIS, open in the scenario)
    # and a fixed level (a line across the river at 850 m) from layers with their fields.
    ring = [QgsPointXY(-112.06, 36.055), QgsPointXY(-112.03, 36.055), QgsPointXY(-112.03, 36.085),
            QgsPointXY(-112.06, 36.085)]
    dam = memory_layer("Polygon?crs=EPSG:4326&field=surface:double", "reservoir",
                       [QgsGeometry.fromPolygonXY([ring + ring[:1]])], [[900.0]])
    level = memory_layer("LineString?crs=EPSG:4326&field=name:string&field=stage:double", "stage",
                         [QgsGeometry.fromPolylineXY(line)], [["river stage", 850.0]])
    results = processing.run("strata:flood", dict(params, INFLOWS=None, GAUGES=None, DAM_BREAKS=dam,
                                                  DAM_SURFACE_FIELD="surface", LEVELS=level, LEVEL_FIELD="stage",
                                                  OUTPUT=os.path.join(work, "dam")),
                             context=QgsProcessingContext(), feedback=QgsProcessingFeedback())
    with open(results["SCENARIO"], "rb") as f:
        water = tomllib.load(f)["water"]
    check(water["dam_break"] == [{"polygon_xy": [[p.x(), p.y()] for p in ring], "surface": "900.0 m"}],
          "the dam-break polygon and its field's surface reach the scenario")
    check(water["level"][0]["line_xy"] == [[p.x(), p.y()] for p in line] and water["level"][0]["name"] == "river stage"
          and water["level"][0]["stage"] == [[0, 850.0], [900.0, 850.0]], "the level line, its name and stage")
    dam_depth = values(results["MAX_DEPTH"])
    check(np.nanmax(dam_depth) > 10, f"the released reservoir floods ({np.nanmax(dam_depth):.1f} m deep at most)")

    # Erosion what-if: a short cloudburst on Rainier's flank at 450 m cells.
    rainier = QgsRasterLayer(os.path.join(data, "rainier", "mt_rainier_90m.tif"), "rainier")
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    results = processing.run("strata:erosion", {
        "DEM": rainier, "EXTENT": "-121.76,-121.56,46.70,46.86 [EPSG:4326]", "CELL_SIZE": 450, "RAIN": 40,
        "RAIN_HOURS": 0.5, "DURATION": 0.5, "BACKEND": 0, "PLOTS": False, "OUTPUT": os.path.join(work, "erosion")},
        context=context, feedback=feedback)
    layers = loaded_layers(context, feedback)
    change = layers.get("TERRAIN_CHANGE")
    check(change is not None and change.renderer().type() == "singlebandpseudocolor" and
          change.crs() == rainier.crs(), "erosion: the terrain change loads styled in the DEM's CRS")
    cut = values(results["TERRAIN_CHANGE"])
    check(np.nanmin(cut) < 0 < np.nanmax(cut), f"erosion: cut {np.nanmin(cut):.2e} m, fill {np.nanmax(cut):.2e} m")

    # Ingest and Render (the strata command).
    store = processing.run("strata:ingest", {"DEM": dem, "MAX_ERROR": 1.0, "OUTPUT": os.path.join(work, "store")},
                           feedback=feedback)["OUTPUT"]
    check(os.path.isfile(os.path.join(store, "manifest.toml")), f"Ingest DEM to store wrote {store}")
    picture = os.path.join(work, "canyon.png")
    processing.run("strata:render", {"DEM": dem, "STORE": store, "CAMERA": "-112.1,36.1 [EPSG:4326]", "AGL": 3000,
                                     "PITCH": -25, "WIDTH": 320, "HEIGHT": 180, "OUTPUT": picture}, feedback=feedback)
    image = gdal.Open(picture).ReadAsArray().astype(np.float64)
    check(image.shape[1:] == (180, 320) and image[:3].std() > 10, f"Render picture drew {picture} (std {image[:3].std():.0f})")
    try:
        processing.run("strata:render", {"DEM": dem, "WIDTH": 32, "HEIGHT": 18, "OUTPUT": picture}, feedback=feedback)
        check(False, "Render refuses to replace a picture unasked")
    except QgsProcessingException as e:
        check("exists" in str(e), f"Render refuses to replace a picture unasked: {str(e).splitlines()[0]}")

    # A Processing model (what the graphical modeller builds) with the Flood algorithm as its child.
    model = QgsProcessingModelAlgorithm("canyon flood", "tests")
    model.addModelParameter(QgsProcessingParameterRasterLayer("dem", "DEM"), QgsProcessingModelParameter("dem"))
    child = QgsProcessingModelChildAlgorithm("strata:flood")
    child.setChildId("flood")
    child.addParameterSources("DEM", [QgsProcessingModelChildParameterSource.fromModelParameter("dem")])
    for key in ("EXTENT", "CELL_SIZE", "INFLOWS", "INFLOW_PEAK_FIELD", "HYDROGRAPH", "MANNING", "CLOSED_EDGES", "GAUGES", "GAUGE_NAME_FIELD",
                "DURATION", "OUTPUT_INTERVAL",
                "BACKEND", "PLOTS"):
        child.addParameterSources(key, [QgsProcessingModelChildParameterSource.fromStaticValue(params[key])])
    child.addParameterSources("OUTPUT", [QgsProcessingModelChildParameterSource.fromStaticValue(
        os.path.join(work, "model"))])
    out = QgsProcessingModelOutput("depth", "Max depth")
    out.setChildOutputName("MAX_DEPTH")
    out.setChildId("flood")
    child.setModelOutputs({"depth": out})
    model.addChildAlgorithm(child)
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    results, ok = model.run({"dem": dem}, context, feedback)
    depth_model = values(os.path.join(work, "model", "maps", "max_depth.tif"))
    check(ok and same(depth_model, depth), "a model running the Flood algorithm gives the same max depth")

    plugin.unload()
    print("qgis provider: all checks passed")
    sys.stdout.flush()
    # PyQGIS tears its layers and providers down in an order that crashes at interpreter exit
    # (Debian's 3.22, as tests/scenario/qgis/check_styles.py notes): leave without it.
    os._exit(0)


if __name__ == "__main__":
    main()
