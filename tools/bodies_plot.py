#!/usr/bin/env python3
"""Draws runs of the bodies' validation scenes against their references (docs/bodies.md).

    tools/bodies_plot.py sinking RUN_DIR[=LABEL] [...] -o FILE.png
        scenes/sinking_cylinder_2d.toml: the cylinder's displacement from its release against
        T = (t - release) sqrt(g/R), with Fekken (2004) and Moyo & Greenhow (2000).
    tools/bodies_plot.py spheric10 RUN_DIR[=LABEL] [...] -o FILE.png
        scenes/sloshing_spheric10_2d.toml: the left-wall sensor's pressure (probes.csv, column
        `sensor`) against time, with the experiment's impact onsets.

Reads bodies.csv or probes.csv of each run. Needs matplotlib (a dependency of pyvista, which
tools/setup.sh installs).
"""

import argparse
import csv
import math
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# T = 1..7 (../shared/VALIDATION.md, "Sinking half-submerged cylinder").
FEKKEN = [-0.198, -0.649, -1.166, -1.630, -2.041, -2.455, -2.895]
MOYO_GREENHOW = [-0.154, -0.657, -1.292, -1.965, -2.650, -3.374, -4.142]
# SPHERIC benchmark 10, low filling, lateral impacts (../shared/VALIDATION.md).
SPHERIC_ONSETS = [2.375, 4.050, 5.672, 7.303]


def runs(arguments):
    """(directory, label) of each RUN_DIR[=LABEL]."""
    for argument in arguments:
        directory, _, label = argument.partition("=")
        yield pathlib.Path(directory), label or pathlib.Path(directory).name


def sinking(arguments, release, radius, gravity):
    figure, axes = plt.subplots(figsize=(6, 4))
    ts = range(1, 8)
    axes.plot(ts, FEKKEN, "s--", color="grey", label="Fekken 2004 (numerical)")
    axes.plot(ts, MOYO_GREENHOW, "o--", color="black", label="Moyo & Greenhow 2000 (experiment)")
    for directory, label in runs(arguments):
        with open(directory / "bodies.csv") as f:
            rows = [(float(r["time"]), float(r["y"])) for r in csv.DictReader(f) if r["body"] == "0"]
        held = min(rows, key=lambda r: abs(r[0] - release))[1]
        after = [(r[0], r[1]) for r in rows if r[0] >= release]
        axes.plot([(t - release) * math.sqrt(gravity / radius) for t, _ in after],
                  [y - held for _, y in after], label=f"isph {label}")
    axes.set_xlabel("T = (t − release) √(g/R)")
    axes.set_ylabel("displacement [m]")
    axes.set_xlim(0, 7)
    axes.legend()
    axes.grid(alpha=0.3)
    return figure


def spheric10(arguments):
    figure, axes = plt.subplots(figsize=(8, 3.5))
    for directory, label in runs(arguments):
        with open(directory / "probes.csv") as f:
            rows = [(float(r["time"]), float(r["sensor"])) for r in csv.DictReader(f)]
        axes.plot([t for t, _ in rows], [p / 1000 for _, p in rows], lw=0.7, label=f"isph {label}")
    for k, onset in enumerate(SPHERIC_ONSETS):
        axes.axvline(onset, color="black", ls="--", lw=0.8,
                     label="experiment's onsets" if k == 0 else None)
    axes.axhline(1.0, color="grey", lw=0.5)
    axes.set_xlabel("t [s]")
    axes.set_ylabel("sensor pressure [kPa]")
    axes.legend(loc="upper left")
    axes.grid(alpha=0.3)
    return figure


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("case", choices=["sinking", "spheric10"])
    parser.add_argument("runs", nargs="+")
    parser.add_argument("-o", "--output", required=True)
    parser.add_argument("--release", type=float, default=1.0)
    parser.add_argument("--radius", type=float, default=1.0)
    parser.add_argument("--gravity", type=float, default=9.81)
    a = parser.parse_args()
    if a.case == "sinking":
        figure = sinking(a.runs, a.release, a.radius, a.gravity)
    else:
        figure = spheric10(a.runs)
    figure.tight_layout()
    figure.savefig(a.output, dpi=120)


if __name__ == "__main__":
    main()
