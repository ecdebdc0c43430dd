#!/usr/bin/python3
"""Draws a Strata run's GeoTIFF maps as PNG pictures over a hillshade of the terrain.

    plot_maps.py RUN_FOLDER

Reads RUN/maps/elevation.tif and every other RUN/maps/*.tif (max_depth, max_speed, arrival_time,
inundation_duration, final_depth, terrain_change, exposed_material, suspended_sediment) and writes RUN/plots/<name>.png with lon/lat
(or CRS) axes, a colour bar with units, and the terrain's hillshade underneath.
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.colors  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from osgeo import gdal  # noqa: E402

gdal.UseExceptions()

STYLE = {
    "max_depth": ("Maximum water depth", "m", "Blues", None),
    "final_depth": ("Water depth at the end", "m", "Blues", None),
    "max_speed": ("Maximum flow speed", "m/s", "inferno", None),
    "arrival_time": ("Arrival time of the water", "h", "viridis_r", 1 / 3600.0),
    "inundation_duration": ("Time under water", "h", "magma_r", 1 / 3600.0),
    "terrain_change": ("Terrain change (erosion < 0 < deposition)", "m", "RdBu", None),
    "exposed_material": ("Exposed material at the end", "layer", "tab10", None),
    "suspended_sediment": ("Suspended sediment at the end", "m", "YlOrBr", None),
}


# A figure is ~1000 pixels wide: a larger map is read at every k-th cell (GDAL's nearest), so
# that a region of any size plots in bounded memory and time.
MAX_CELLS = 2048


def read(path):
    ds = gdal.Open(str(path))
    band = ds.GetRasterBand(1)
    k = max(1, -(-max(ds.RasterXSize, ds.RasterYSize) // MAX_CELLS))
    bx, by = -(-ds.RasterXSize // k), -(-ds.RasterYSize // k)
    a = band.ReadAsArray(buf_xsize=bx, buf_ysize=by,
                         resample_alg=gdal.GRIORA_NearestNeighbour).astype(np.float64)
    nodata = band.GetNoDataValue()
    if nodata is not None:
        a[a == nodata] = np.nan
    gt = list(ds.GetGeoTransform())
    gt[1] *= ds.RasterXSize / bx  # the cells as read (hillshade's slopes)
    gt[5] *= ds.RasterYSize / by
    extent = [gt[0], gt[0] + gt[1] * bx, gt[3] + gt[5] * by, gt[3]]
    geographic = ds.GetSpatialRef() is not None and ds.GetSpatialRef().IsGeographic()
    return a, extent, gt, geographic


def hillshade(z, gt, geographic):
    dx = abs(gt[1]) * (111320.0 * np.cos(np.radians(gt[3])) if geographic else 1.0)
    dy = abs(gt[5]) * (110540.0 if geographic else 1.0)
    gy, gx = np.gradient(z, dy, dx)
    slope = np.arctan(np.hypot(gx, gy))
    aspect = np.arctan2(-gx, gy)
    az, alt = np.radians(315.0), np.radians(45.0)
    return np.clip(np.sin(alt) * np.cos(slope) + np.cos(alt) * np.sin(slope) * np.cos(az - aspect), 0, 1)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    run = Path(sys.argv[1])
    z, extent, gt, geographic = read(run / "maps" / "elevation.tif")
    shade = hillshade(z, gt, geographic)
    out = run / "plots"
    out.mkdir(exist_ok=True)
    for name, (title, unit, cmap, scale) in STYLE.items():
        path = run / "maps" / (name + ".tif")
        if not path.exists():
            continue
        a, _, _, _ = read(path)
        if scale:
            a = a * scale
        a = np.ma.masked_invalid(a)
        if name.endswith("depth") or name in ("inundation_duration", "suspended_sediment"):
            a = np.ma.masked_less_equal(a, 0)
        fig, ax = plt.subplots(figsize=(7.5, 6.2))
        ax.imshow(shade, extent=extent, cmap="gray", vmin=0, vmax=1)
        if a.count() > 0:
            if name == "terrain_change":
                # The colour range is the 99th percentile of the cells that changed, not the largest
                # change: a few cells of tens of metres (a pit filled, a bank slumped) would
                # otherwise wash out every channel. Beyond it the colour saturates (the colour bar
                # says so with its arrows).
                changed = np.abs(a.compressed())
                changed = changed[changed > 0]
                lim = float(np.percentile(changed, 99)) if changed.size else 1.0
                im = ax.imshow(a, extent=extent, cmap=cmap, vmin=-lim, vmax=lim, alpha=0.85)
                fig.colorbar(im, ax=ax, shrink=0.8, extend="both", label=f"{title.lower()} ({unit})")
                im = None
            elif name == "exposed_material":
                # One colour per layer, the material's own (STRATA_COLOUR_k), labelled with its name
                # (STRATA_MATERIAL_k); maps without them get tab10 and layer numbers.
                meta = gdal.Open(str(path)).GetMetadata()
                n = 0
                while f"STRATA_MATERIAL_{n}" in meta and f"STRATA_COLOUR_{n}" in meta:
                    n += 1
                if n > 0:
                    colours = [tuple(float(c) for c in meta[f"STRATA_COLOUR_{k}"].split(",")) for k in range(n)]
                    names = [f"{k + 1}: {meta[f'STRATA_MATERIAL_{k}']}" for k in range(n)]
                    im = ax.imshow(a, extent=extent, cmap=matplotlib.colors.ListedColormap(colours), vmin=-0.5,
                                   vmax=n - 0.5, alpha=0.9, interpolation="nearest")
                    bar = fig.colorbar(im, ax=ax, shrink=0.8, ticks=range(n), label="layer: material")
                    bar.ax.set_yticklabels(names)
                    im = None
                else:
                    im = ax.imshow(a, extent=extent, cmap=cmap, vmin=-0.5, vmax=9.5, alpha=0.85,
                                   interpolation="nearest")
            else:
                im = ax.imshow(a, extent=extent, cmap=cmap, alpha=0.85)
            if im is not None:
                fig.colorbar(im, ax=ax, shrink=0.8, label=f"{title.lower()} ({unit})")
        ax.set_title(title)
        ax.set_xlabel("longitude (°)" if geographic else "x (m)")
        ax.set_ylabel("latitude (°)" if geographic else "y (m)")
        fig.tight_layout()
        tmp = out / (name + ".tmp.png")
        fig.savefig(tmp, dpi=100)
        tmp.replace(out / (name + ".png"))
        plt.close(fig)


if __name__ == "__main__":
    main()
