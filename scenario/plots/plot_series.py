#!/usr/bin/python3
"""Plots a Strata run's time series (series.csv) as PNG figures with matplotlib.

    plot_series.py RUN/series.csv OUTDIR

Writes water.png (stored volume, cumulative inflow/rain/outflow), area.png (flooded area),
balance.png (volume balance error) and, when the run moved sediment, sediment.png; with
gauges.csv or sections.csv beside series.csv, gauges.png (depth and water level at each gauge)
and sections.png (discharge across each section, and the volume that crossed).
"""
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot_series: {path}: no rows")
    cols = {k: [float(r[k]) for r in rows] for k in rows[0]}
    return cols


def hours(cols):
    return [t / 3600.0 for t in cols["time_s"]]


def save(fig, out, name):
    fig.tight_layout()
    tmp = out / (name + ".tmp.png")
    fig.savefig(tmp, dpi=110)
    tmp.replace(out / (name + ".png"))
    plt.close(fig)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    cols = read(sys.argv[1])
    out = Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    t = hours(cols)

    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(t, [v / 1e6 for v in cols["water_volume_m3"]], label="stored", lw=2)
    for key, label in (("inflow_m3", "inflow (cumulative)"), ("rain_m3", "rain (cumulative)"),
                       ("outflow_m3", "outflow (cumulative)"), ("evaporation_m3", "evaporated (cumulative)"),
                       ("infiltration_m3", "infiltrated (cumulative)")):
        if key in cols and max(cols[key]) > 0:
            ax.plot(t, [v / 1e6 for v in cols[key]], label=label, ls="--")
    ax.set_xlabel("time (h)")
    ax.set_ylabel("volume (million m³)")
    ax.set_title("Water volume")
    ax.grid(alpha=0.3)
    ax.legend()
    save(fig, out, "water")

    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(t, cols["flooded_area_km2"], color="tab:blue", lw=2)
    ax.set_xlabel("time (h)")
    ax.set_ylabel("flooded area (km²)")
    ax.set_title("Flooded area (depth above the wet threshold)")
    ax.grid(alpha=0.3)
    save(fig, out, "area")

    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(t, cols["balance_error_rel"], color="tab:red")
    ax.set_xlabel("time (h)")
    ax.set_ylabel("(in - out - stored) / in")
    ax.set_title("Volume balance error")
    ax.grid(alpha=0.3)
    save(fig, out, "balance")

    if "eroded_m3" in cols and max(cols["eroded_m3"]) > 0:
        fig, ax = plt.subplots(figsize=(7, 4))
        for key, label in (("eroded_m3", "eroded"), ("deposited_m3", "deposited"), ("sediment_m3", "in suspension")):
            ax.plot(t, cols[key], label=label)
        ax.set_xlabel("time (h)")
        ax.set_ylabel("volume (m³)")
        ax.set_title("Material moved")
        ax.grid(alpha=0.3)
        ax.legend()
        save(fig, out, "sediment")

    probes(Path(sys.argv[1]).parent, out)


def by_name(path, key):
    """Rows of a long-format CSV grouped by the probe's name, in file order."""
    groups = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            groups.setdefault(r[key], []).append(r)
    return groups


def number(text):
    return float(text) if text != "" else float("nan")


def two_panels(path, key, title, panels, out, name):
    """One figure of a long-format probe CSV: a line per probe in each of two panels, over time.
    `panels`: two (column, y label) pairs."""
    groups = by_name(path, key)
    fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for probe, rows in groups.items():
        t = [float(r["time_s"]) / 3600.0 for r in rows]
        for ax, (column, _) in zip(axes, panels):
            ax.plot(t, [number(r[column]) for r in rows], label=probe)
    for ax, (_, label) in zip(axes, panels):
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].set_title(title)
    axes[1].set_xlabel("time (h)")
    axes[0].legend()
    save(fig, out, name)


def probes(run, out):
    if (run / "gauges.csv").exists():
        two_panels(run / "gauges.csv", "gauge", "Gauges", [("depth_m", "depth (m)"), ("level_m", "water level (m)")],
                   out, "gauges")
    if (run / "sections.csv").exists():
        two_panels(run / "sections.csv", "section", "Sections (positive from the line's left to its right)",
                   [("discharge_m3_s", "discharge (m³/s)"), ("volume_m3", "volume across (m³)")], out, "sections")

if __name__ == "__main__":
    main()
