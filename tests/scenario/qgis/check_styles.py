#!/usr/bin/python3
"""Loads a Strata run folder's maps into headless QGIS (python3-qgis) as a user dragging the
folder in would: each map with the .qml style beside it, the flood outline from its GeoPackage.
Fails unless every style loads and gives the renderer Strata wrote, the outline has the run's CRS
and its features' area_m2 add up to `expected_area_m2`. With OUT.png, draws the layers to it.

    check_styles.py RUN_DIR EXPECTED_AREA_M2 [OUT.png]
"""
import os
import sys
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from qgis.core import (QgsApplication, QgsMapRendererParallelJob, QgsMapSettings,  # noqa: E402
                       QgsRasterLayer, QgsVectorLayer)
from qgis.PyQt.QtCore import QSize  # noqa: E402
from qgis.PyQt.QtGui import QColor  # noqa: E402


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    run = Path(sys.argv[1])
    expected = float(sys.argv[2])
    app = QgsApplication([], False)
    app.initQgis()
    failures = []
    layers = []
    for tif in sorted((run / "maps").glob("*.tif")):
        layer = QgsRasterLayer(str(tif), tif.stem)
        if not layer.isValid():
            failures.append(f"{tif}: QGIS cannot open it")
            continue
        message, ok = layer.loadDefaultStyle()
        renderer = layer.renderer().type() if layer.renderer() else None
        if not ok or renderer != "singlebandpseudocolor":
            failures.append(f"{tif}: style not applied ({message}; renderer {renderer})")
            continue
        shader = layer.renderer().shader().rasterShaderFunction()
        if len(shader.colorRampItemList()) < 4:
            failures.append(f"{tif}: {len(shader.colorRampItemList())} ramp items")
        print(f"{tif.name}: {renderer}, {len(shader.colorRampItemList())} items, "
              f"{shader.minimumValue():.4g} .. {shader.maximumValue():.4g}, CRS {layer.crs().authid()}")
        layers.append(layer)
    gpkg = run / "maps" / "flood_outline.gpkg"
    outline = QgsVectorLayer(f"{gpkg}|layername=flood_outline", "flood_outline", "ogr")
    if not outline.isValid():
        failures.append(f"{gpkg}: QGIS cannot open it")
    else:
        message, ok = outline.loadNamedStyle(str(run / "maps" / "flood_outline.qml"))
        if not ok or outline.renderer().type() != "singleSymbol":
            failures.append(f"{gpkg}: style not applied ({message})")
        area = sum(f["area_m2"] for f in outline.getFeatures())
        crs = outline.crs().authid()
        print(f"flood_outline.gpkg: {outline.featureCount()} features, {area:.1f} m2, CRS {crs}")
        if abs(area - expected) > 1e-6 * expected:
            failures.append(f"{gpkg}: area {area} m2, expected {expected}")
        if layers and crs != layers[0].crs().authid():
            failures.append(f"{gpkg}: CRS {crs}, the maps' {layers[0].crs().authid()}")
    if len(sys.argv) == 4 and layers:
        settings = QgsMapSettings()
        by_name = {l.name(): l for l in layers}
        drawn = [outline] + [by_name[n] for n in ("hazard_rating", "max_depth", "elevation") if n in by_name]
        settings.setLayers(drawn)
        settings.setDestinationCrs(layers[0].crs())
        settings.setExtent(layers[0].extent())
        settings.setOutputSize(QSize(760, 600))
        settings.setBackgroundColor(QColor("white"))
        job = QgsMapRendererParallelJob(settings)
        job.start()
        job.waitForFinished()
        job.renderedImage().save(sys.argv[3])
    for f in failures:
        print("FAIL:", f)
    sys.stdout.flush()
    # PyQGIS tears its layers and providers down in an order that crashes at interpreter exit
    # (Debian's 3.22): leave without it, the answer already given.
    os._exit(1 if failures else 0)


if __name__ == "__main__":
    main()
