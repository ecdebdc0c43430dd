#!/usr/bin/python3
"""The pictures of docs/qgis.md, taken from QGIS itself (Debian's python3-qgis 3.22) under Xvfb:
the Flood what-if dialog filled in for the Grand Canyon, and the styled result in a map canvas
with its layer tree. Run it from the source tree after a build:

    xvfb-run -a -s "-screen 0 1600x1000x24" /usr/bin/python3 docs/examples/qgis_walkthrough.py build OUT_DIR

It runs the flood (the main job's inflow, 50,000 m3/s, for 2 h at the DEM's own 217 m cells, the
river's path breached and the pits filled, the east edge a wall) into OUT_DIR/run and
writes OUT_DIR/qgis_flood_dialog.png and OUT_DIR/qgis_flood_result.png.
"""
import os
import sys

os.environ["GDAL_PAM_ENABLED"] = "NO"  # no .aux.xml of the layers' statistics beside the shared DEMs

from qgis.core import (QgsApplication, QgsFeature, QgsGeometry, QgsHillshadeRenderer, QgsLayerTreeModel, QgsPointXY,
                       QgsProcessingContext, QgsProcessingFeedback, QgsProcessingUtils, QgsProject, QgsRasterLayer,
                       QgsVectorLayer)
from qgis.gui import QgsLayerTreeMapCanvasBridge, QgsLayerTreeView, QgsMapCanvas
from qgis.PyQt.QtCore import QSize, Qt
from qgis.PyQt.QtGui import QImage
from qgis.PyQt.QtWidgets import QHBoxLayout, QWidget


def main():
    build, out = (os.path.abspath(a) for a in sys.argv[1:3])
    source = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    os.makedirs(out, exist_ok=True)
    app = QgsApplication([], True)
    app.initQgis()
    sys.path.append(os.path.join(QgsApplication.pkgDataPath(), "python", "plugins"))
    import processing
    from processing.core.Processing import Processing
    from processing.gui.AlgorithmDialog import AlgorithmDialog
    Processing.initialize()
    sys.path.insert(0, os.path.join(build, "python", "qgis"))
    import strata_processing
    plugin = strata_processing.classFactory(None)  # kept: it owns the provider
    plugin.initProcessing()

    project = QgsProject.instance()
    dem = QgsRasterLayer(os.path.join(source, "..", "shared", "data", "grand_canyon", "grand_canyon_512.tif"),
                         "grand_canyon_512")
    inflows = QgsVectorLayer("LineString?crs=EPSG:4326&field=name:string&field=peak:double", "inflows", "memory")
    f = QgsFeature(inflows.fields())
    f.setGeometry(QgsGeometry.fromPolylineXY([QgsPointXY(-112.0225, 36.063), QgsPointXY(-112.0225, 36.08)]))
    f.setAttributes(["Colorado", 50000.0])
    inflows.dataProvider().addFeatures([f])
    project.addMapLayers([dem, inflows])
    params = {"DEM": dem, "EXTENT": "-112.75,-112.001,36.01,36.45 [EPSG:4326]", "INFLOWS": inflows,
              "INFLOW_PEAK_FIELD": "peak", "HYDROGRAPH": [0, 0, 0.5, 1, 2, 1], "MANNING": 0.04, "CLOSED_EDGES": [1], "DURATION": 2,
              "FILL_DEPRESSIONS": True, "BREACH_INFLOWS": True, "BACKEND": 0, "OUTPUT": os.path.join(out, "run")}

    # The dialog as a user sees it from the Processing toolbox, filled in.
    alg = QgsApplication.processingRegistry().algorithmById("strata:flood")
    dialog = AlgorithmDialog(alg.create(), False, None)
    dialog.setParameters(params)
    dialog.show()
    dialog.resize(QSize(900, 900))  # after show: the dialog restores its last geometry when shown
    app.processEvents()
    dialog.grab().save(os.path.join(out, "qgis_flood_dialog.png"))
    dialog.hide()

    # The run, and its outputs loaded as QGIS loads them on completion (each with its style).
    context = QgsProcessingContext()
    context.setProject(project)
    feedback = QgsProcessingFeedback()
    processing.run("strata:flood", params, context=context, feedback=feedback)
    loaded = []
    for layer_source, details in context.layersToLoadOnCompletion().items():
        layer = QgsProcessingUtils.mapLayerFromString(layer_source, context)
        layer.setName(details.name)
        details.postProcessor().postProcessLayer(layer, context, feedback)
        loaded.append((details.outputName, layer))
    order = ["FLOOD_OUTLINE", "MAX_DEPTH", "HAZARD_RATING", "ARRIVAL_TIME", "MAX_SPEED"]
    loaded.sort(key=lambda item: order.index(item[0]))
    for name, layer in loaded:
        project.addMapLayer(layer)
        if name not in ("FLOOD_OUTLINE", "MAX_DEPTH"):
            project.layerTreeRoot().findLayer(layer.id()).setItemVisibilityChecked(False)
    hillshade = QgsHillshadeRenderer(dem.dataProvider(), 1, 315, 45)
    hillshade.setZFactor(1 / 111320)  # elevations in m over a grid in degrees
    dem.setRenderer(hillshade)
    dem.dataProvider().setZoomedInResamplingMethod(dem.dataProvider().ResamplingMethod.Bilinear)
    project.layerTreeRoot().findLayer(inflows.id()).setItemVisibilityChecked(True)
    root = project.layerTreeRoot()
    for layer in (inflows, dem):  # inflows on top, the hillshade at the bottom
        node = root.findLayer(layer.id())
        clone = node.clone()
        (root.insertChildNode(0, clone) if layer is inflows else root.addChildNode(clone))
        node.parent().removeChildNode(node)

    window = QWidget()
    box = QHBoxLayout(window)
    tree = QgsLayerTreeView()
    model = QgsLayerTreeModel(root)
    tree.setModel(model)
    canvas = QgsMapCanvas()
    canvas.setCanvasColor(Qt.white)
    window.bridge = QgsLayerTreeMapCanvasBridge(root, canvas)  # kept: it keeps the canvas's layers in step
    canvas.setDestinationCrs(dem.crs())
    box.addWidget(tree, 1)
    box.addWidget(canvas, 3)
    window.resize(QSize(1400, 720))
    window.show()
    canvas.setExtent(dict(loaded)["MAX_DEPTH"].extent())  # the region
    canvas.refresh()
    canvas.waitWhileRendering()
    app.processEvents()
    canvas.waitWhileRendering()
    # 256 colours: the hillshade's noise would make a full-colour PNG four times larger
    window.grab().toImage().convertToFormat(QImage.Format_Indexed8).save(os.path.join(out, "qgis_flood_result.png"))
    print(f"wrote {out}/qgis_flood_dialog.png and {out}/qgis_flood_result.png")
    sys.stdout.flush()
    os._exit(0)  # PyQGIS 3.22 crashes tearing its layers down at interpreter exit


if __name__ == "__main__":
    main()
