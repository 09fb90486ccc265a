#!/usr/bin/env python3
"""Draws the wall pressures of runs of scenes/dam_break_lobovsky_2d.toml (or _3d.toml) against
the experiment of Lobovsky et al. (2014), one panel per sensor (P1-P4), as P/(rho g H) against
t sqrt(g/H), and with --levels the water levels at its gauges H1-H4 as h/H.

    tools/lobovsky_plot.py RUN_DIR[=LABEL] [RUN_DIR[=LABEL] ...] [-o FILE.svg|png]
                           [--levels FILE.svg|png] [--height 0.3] [--density 1000]
                           [--gravity 9.81]

Reads each run's probes.csv (columns P1-P4, and H1-H4 for the levels) and the experiment's
curves from docs/accuracy/lobovsky_2014/sensor<k>.csv and gauge<k>.csv; shades the plateau
window (T = 3.5-5.5) and the levels' window (0.5-5.5), and marks the onset level (0.1 rho g H)
that `isph measure lobovsky_pressure` uses. Needs matplotlib (a dependency of pyvista, which
tools/setup.sh installs).
"""

import argparse
import csv
import math
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DATA = pathlib.Path(__file__).resolve().parent.parent / "docs" / "accuracy" / "lobovsky_2014"
HEIGHTS_MM = {1: 3, 2: 15, 3: 30, 4: 80}
ONSET_LEVEL = 0.1
PLATEAU = (3.5, 5.5)
LEVEL_WINDOW = (0.5, 5.5)
GAUGES_MM = {1: 300, 2: 865, 3: 1114, 4: 1362.5}


def experiment(name):
    """(T, value) of the experiment's curve docs/accuracy/lobovsky_2014/NAME.csv, skipping the
    comment lines and the header."""
    rows = [l for l in (DATA / f"{name}.csv").read_text().splitlines() if not l.startswith("#")]
    t, v = [], []
    for row in list(csv.reader(rows))[1:]:
        t.append(float(row[0]))
        v.append(float(row[1]))
    return t, v


def run(directory, column, time_scale, to_value):
    """(T, to_value(x)) of the values x of a run's probes.csv column."""
    with open(pathlib.Path(directory) / "probes.csv") as f:
        rows = list(csv.DictReader(f))
    t = [float(r["time"]) * time_scale for r in rows]
    v = [to_value(float(r[column])) for r in rows]
    return t, v


def panels(args, time_scale, name, column, to_value, window, ylim, ylabel, title):
    """Four panels, the experiment's curve NAME<k> against each run's probe COLUMN<k>."""
    fig, axes = plt.subplots(4, 1, figsize=(9, 12), sharex=True)
    for k, ax in zip(range(1, 5), axes):
        t, v = experiment(f"{name}{k}")
        ax.plot(t, v, color="black", lw=1.2, label="Lobovsky et al. 2014")
        for spec in args.runs:
            directory, _, label = spec.partition("=")
            t, v = run(directory, f"{column}{k}", time_scale, to_value)
            ax.plot(t, v, lw=1.0, label=label or directory)
        ax.axvspan(*window, color="0.9", zorder=0)
        ax.set_ylim(*ylim)
        ax.set_ylabel(ylabel)
        ax.set_title(title(k), fontsize=10)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, loc="upper right")
    axes[-1].set_xlabel("t √(g/H)")
    return axes


def save(axes, output):
    axes[0].figure.tight_layout()
    axes[0].figure.savefig(output)
    print(output)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", help="RUN_DIR or RUN_DIR=LABEL")
    parser.add_argument("-o", "--output", default="lobovsky.svg")
    parser.add_argument("--levels", help="also draw the gauges' water levels into this file")
    parser.add_argument("--height", type=float, default=0.3, help="column height H [m]")
    parser.add_argument("--density", type=float, default=1000.0)
    parser.add_argument("--gravity", type=float, default=9.81)
    args = parser.parse_args()
    time_scale = math.sqrt(args.gravity / args.height)
    pressure_scale = args.density * args.gravity * args.height

    axes = panels(
        args, time_scale, "sensor", "P", lambda p: p / pressure_scale, PLATEAU, (-0.1, 3.0),
        "P / (ρ g H)", lambda k: f"P{k}: {HEIGHTS_MM[k]} mm above the floor",
    )
    for ax in axes:
        ax.axhline(ONSET_LEVEL, color="0.6", lw=0.6, ls="--")
        ax.set_xlim(2.0, 7.2)
    save(axes, args.output)
    if args.levels:
        # The floor at z = 0, as in the shipped scene.
        axes = panels(
            args, time_scale, "gauge", "H",
            lambda z: 0.0 if math.isnan(z) else z / args.height, LEVEL_WINDOW, (0.0, 1.05),
            "h / H", lambda k: f"H{k}: {GAUGES_MM[k]} mm from the column's wall",
        )
        axes[-1].set_xlim(0.0, 7.2)
        save(axes, args.levels)


if __name__ == "__main__":
    main()
