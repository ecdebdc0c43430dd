#!/usr/bin/python3
"""Draws a Strata run's GeoTIFF maps as PNG pictures over a hillshade of the terrain.

    plot_maps.py RUN_FOLDER

Reads RUN/maps/elevation.tif and every other RUN/maps/*.tif (max_depth, max_speed, arrival_time,
inundation_duration, final_depth, hazard_rating, terrain_change, exposed_material,
suspended_sediment) and writes RUN/plots/<name>.png with lon/lat (or CRS) axes, a colour bar with
units, a scale bar and a north arrow, and the terrain's hillshade underneath. The flood maps are
zoomed to where the water went (the cells max_depth shows wet, with a margin) when that is a small
part of the region, with a locator inset of the whole region; depths are drawn on a log scale from
the shallowest wet cell, in blues that start visibly darker than the hillshade's white.
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.colors  # noqa: E402
import matplotlib.patches  # noqa: E402
import matplotlib.ticker  # noqa: E402
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
    "hazard_rating": ("Flood hazard to people (FD2321 rating)", "class", "hazard", None),
    "terrain_change": ("Terrain change (erosion < 0 < deposition)", "m", "RdBu", None),
    "conditioning": ("DEM changed by conditioning (cut < 0 < raised)", "m", "RdBu", None),
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


FLOOD_MAPS = ("max_depth", "final_depth", "max_speed", "arrival_time", "inundation_duration", "hazard_rating")
# FD2321's classes and their colours (the .qml styles' too).
HAZARD_BOUNDS = [0.0, 0.75, 1.25, 2.0, np.inf]
HAZARD_NAMES = ["low", "moderate", "significant", "extreme"]
HAZARD_COLOURS = ["#fee08b", "#fdae61", "#f46d43", "#a50026"]
# The depth ramp: matplotlib's Blues from 35 % on, so that the shallowest water is a clear blue
# over the hillshade, not near-white.
DEPTH_CMAP = matplotlib.colors.ListedColormap(plt.get_cmap("Blues")(np.linspace(0.35, 1.0, 256)))


def wet_window(run, extent, shape):
    """The extent of the cells max_depth.tif shows wet, with a margin of a tenth of its size (at
    least 3 cells), or None when that covers most of the region or nothing is wet."""
    path = run / "maps" / "max_depth.tif"
    if not path.exists():
        return None
    a, _, _, _ = read(path)
    wet = np.isfinite(a) & (a > 0)
    if not wet.any() or a.shape != shape:
        return None
    rows, cols = np.where(wet)
    ny, nx = a.shape
    my = max(3, (rows.max() - rows.min() + 1) // 10)
    mx = max(3, (cols.max() - cols.min() + 1) // 10)
    r0, r1 = max(0, rows.min() - my), min(ny, rows.max() + 1 + my)
    c0, c1 = max(0, cols.min() - mx), min(nx, cols.max() + 1 + mx)
    if (r1 - r0) * (c1 - c0) > 0.5 * nx * ny:
        return None
    x0, x1, y0, y1 = extent
    sx, sy = (x1 - x0) / nx, (y1 - y0) / ny  # y0 is the bottom: rows count from the top
    return [x0 + c0 * sx, x0 + c1 * sx, y1 - r1 * sy, y1 - r0 * sy]


def nice_length(m):
    """The largest 1, 2 or 5 x 10^k not above m."""
    k = 10 ** np.floor(np.log10(m))
    return max(f * k for f in (1, 2, 5) if f * k <= m)


def scale_bar_and_north(ax, window, geographic):
    x0, x1, y0, y1 = window
    mid_lat = 0.5 * (y0 + y1)
    metres_per_unit = 111320.0 * np.cos(np.radians(mid_lat)) if geographic else 1.0
    length_m = nice_length(0.25 * (x1 - x0) * metres_per_unit)
    length = length_m / metres_per_unit
    bx, by = x0 + 0.05 * (x1 - x0), y0 + 0.06 * (y1 - y0)
    ax.plot([bx, bx + length], [by, by], color="black", lw=3, solid_capstyle="butt")
    ax.plot([bx, bx + length], [by, by], color="white", lw=1, solid_capstyle="butt")
    label = f"{length_m / 1000:g} km" if length_m >= 1000 else f"{length_m:g} m"
    ax.text(bx + 0.5 * length, by + 0.02 * (y1 - y0), label, ha="center", va="bottom", fontsize=9,
            bbox=dict(facecolor="white", alpha=0.7, edgecolor="none", pad=1))
    nx, ny = x1 - 0.06 * (x1 - x0), y1 - 0.16 * (y1 - y0)
    ax.annotate("N", xy=(nx, ny + 0.1 * (y1 - y0)), xytext=(nx, ny), ha="center", va="top", fontsize=11,
                fontweight="bold", arrowprops=dict(facecolor="black", width=3, headwidth=9, headlength=8))


def locator(inset, shade, extent, window):
    inset.imshow(shade, extent=extent, cmap="gray", vmin=0, vmax=1)
    x0, x1, y0, y1 = window
    inset.add_patch(matplotlib.patches.Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, edgecolor="red", lw=1.5))
    inset.set_xticks([])
    inset.set_yticks([])
    inset.set_title("region", fontsize=7)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    run = Path(sys.argv[1])
    z, extent, gt, geographic = read(run / "maps" / "elevation.tif")
    shade = hillshade(z, gt, geographic)
    out = run / "plots"
    out.mkdir(exist_ok=True)
    window = wet_window(run, extent, z.shape)
    # A comparison folder (strata compare) holds NAME_difference.tif: B - A, drawn diverging.
    styles = dict(STYLE)
    for name, (title, unit, _, scale) in STYLE.items():
        styles[name + "_difference"] = ("Change in " + title[0].lower() + title[1:] + " (B − A)", unit, "RdBu", scale)
    for extra in ("elevation",):
        styles[extra + "_difference"] = ("Change in the bed elevation (B − A)", "m", "RdBu", None)
    for name, (title, unit, cmap, scale) in styles.items():
        path = run / "maps" / (name + ".tif")
        if not path.exists():
            continue
        a, _, _, _ = read(path)
        if scale:
            a = a * scale
        a = np.ma.masked_invalid(a)
        if name.endswith("_difference"):
            a = np.ma.masked_equal(a, 0)  # unchanged cells show the terrain
        elif name.endswith("depth") or name in ("inundation_duration", "suspended_sediment"):
            a = np.ma.masked_less_equal(a, 0)
        zoom = window if name in FLOOD_MAPS else None
        if zoom:
            # The map on the left; on the right the locator above the colour bar.
            fig = plt.figure(figsize=(9.0, 6.2))
            grid = fig.add_gridspec(2, 2, width_ratios=[3.2, 1], height_ratios=[1, 1.6])
            ax = fig.add_subplot(grid[:, 0])
            locator(fig.add_subplot(grid[0, 1]), shade, extent, zoom)
            cax = fig.add_subplot(grid[1, 1])
            cax.set_box_aspect(6)
        else:
            fig, ax = plt.subplots(figsize=(7.5, 6.2))
            cax = None

        def colorbar(im, **kw):
            return fig.colorbar(im, cax=cax, **kw) if cax else fig.colorbar(im, ax=ax, shrink=0.8, **kw)

        ax.imshow(shade, extent=extent, cmap="gray", vmin=0, vmax=1)
        if a.count() > 0:
            if name in ("terrain_change", "conditioning") or name.endswith("_difference"):
                # The colour range is the 99th percentile of the cells that changed, not the largest
                # change: a few cells of tens of metres (a pit filled, a bank slumped) would
                # otherwise wash out every channel. Beyond it the colour saturates (the colour bar
                # says so with its arrows).
                changed = np.abs(a.compressed())
                changed = changed[changed > 0]
                lim = float(np.percentile(changed, 99)) if changed.size else 1.0
                im = ax.imshow(a, extent=extent, cmap=cmap, vmin=-lim, vmax=lim, alpha=0.85)
                colorbar(im, extend="both", label=f"{title[0].lower() + title[1:]} ({unit})")
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
                    bar = colorbar(im, ticks=range(n), label="layer: material")
                    bar.ax.set_yticklabels(names)
                    im = None
                else:
                    im = ax.imshow(a, extent=extent, cmap=cmap, vmin=-0.5, vmax=9.5, alpha=0.85,
                                   interpolation="nearest")
            elif name == "hazard_rating" and not name.endswith("_difference"):
                classes = np.ma.masked_array(np.digitize(a.filled(0), HAZARD_BOUNDS[1:4]), mask=a.mask)
                im = ax.imshow(classes, extent=extent, cmap=matplotlib.colors.ListedColormap(HAZARD_COLOURS),
                               vmin=-0.5, vmax=3.5, alpha=0.9, interpolation="nearest")
                bar = colorbar(im, ticks=range(4), label="hazard class (HR bounds 0.75, 1.25, 2)")
                bar.ax.set_yticklabels(HAZARD_NAMES)
                im = None
            elif name.endswith("depth"):
                # From the run's wet threshold (the map's STRATA_WET_THRESHOLD_M): shallower cells
                # are not flooded and are not drawn.
                meta = gdal.Open(str(path)).GetMetadata()
                wet = float(meta.get("STRATA_WET_THRESHOLD_M", "0"))
                if wet > 0:
                    a = np.ma.masked_less_equal(a, wet)
                lo, hi = (float(a.min()), float(a.max())) if a.count() else (1.0, 2.0)
                norm = matplotlib.colors.LogNorm(vmin=lo, vmax=max(hi, 2 * lo))
                im = ax.imshow(a, extent=extent, cmap=DEPTH_CMAP, norm=norm, alpha=0.9, interpolation="nearest")
            else:
                im = ax.imshow(a, extent=extent, cmap=cmap, alpha=0.85)
            if im is not None:
                colorbar(im, label=f"{title[0].lower() + title[1:]} ({unit})")
        if zoom:
            ax.set_xlim(zoom[0], zoom[1])
            ax.set_ylim(zoom[2], zoom[3])
        ax.xaxis.set_major_locator(matplotlib.ticker.MaxNLocator(5))
        ax.ticklabel_format(useOffset=False)  # -112.08, not -0.08 and "-1.12e2" in a corner
        scale_bar_and_north(ax, zoom or extent, geographic)
        ax.set_title(title + ("\n(zoomed to where the water went)" if zoom else ""))
        ax.set_xlabel("longitude (°)" if geographic else "x (m)")
        ax.set_ylabel("latitude (°)" if geographic else "y (m)")
        fig.tight_layout()
        tmp = out / (name + ".tmp.png")
        fig.savefig(tmp, dpi=100, bbox_inches="tight")
        tmp.replace(out / (name + ".png"))
        plt.close(fig)


if __name__ == "__main__":
    main()
