#!/usr/bin/env python3
"""Draws the wall pressures of runs of scenes/dam_break_lobovsky_2d.toml against the experiment
of Lobovsky et al. (2014), one panel per sensor (P1-P4), as P/(rho g H) against t sqrt(g/H).

    tools/lobovsky_plot.py RUN_DIR[=LABEL] [RUN_DIR[=LABEL] ...] [-o FILE.svg|png]
                           [--height 0.3] [--density 1000] [--gravity 9.81]

Reads each run's probes.csv (columns P1-P4) and the experiment's curves from
docs/accuracy/lobovsky_2014/sensor<k>.csv; shades the plateau window (T = 3.5-5.5) and marks the
onset level (0.1 rho g H) that `isph measure lobovsky_pressure` uses. Needs matplotlib (a
dependency of pyvista, which tools/setup.sh installs).
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


def experiment(k):
    """(T, P/(rho g H)) of sensor k, skipping the comment lines and the header."""
    rows = [l for l in (DATA / f"sensor{k}.csv").read_text().splitlines() if not l.startswith("#")]
    t, p = [], []
    for row in list(csv.reader(rows))[1:]:
        t.append(float(row[0]))
        p.append(float(row[1]))
    return t, p


def run(directory, k, time_scale, pressure_scale):
    """(T, P/(rho g H)) of probe Pk of a run."""
    with open(pathlib.Path(directory) / "probes.csv") as f:
        rows = list(csv.DictReader(f))
    t = [float(r["time"]) * time_scale for r in rows]
    p = [float(r[f"P{k}"]) / pressure_scale for r in rows]
    return t, p


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", help="RUN_DIR or RUN_DIR=LABEL")
    parser.add_argument("-o", "--output", default="lobovsky.svg")
    parser.add_argument("--height", type=float, default=0.3, help="column height H [m]")
    parser.add_argument("--density", type=float, default=1000.0)
    parser.add_argument("--gravity", type=float, default=9.81)
    args = parser.parse_args()
    time_scale = math.sqrt(args.gravity / args.height)
    pressure_scale = args.density * args.gravity * args.height

    fig, axes = plt.subplots(4, 1, figsize=(9, 12), sharex=True)
    for k, ax in zip(range(1, 5), axes):
        t, p = experiment(k)
        ax.plot(t, p, color="black", lw=1.2, label="Lobovsky et al. 2014")
        for spec in args.runs:
            directory, _, label = spec.partition("=")
            t, p = run(directory, k, time_scale, pressure_scale)
            ax.plot(t, p, lw=1.0, label=label or directory)
        ax.axvspan(*PLATEAU, color="0.9", zorder=0)
        ax.axhline(ONSET_LEVEL, color="0.6", lw=0.6, ls="--")
        ax.set_xlim(2.0, 7.2)
        ax.set_ylim(-0.1, 3.0)
        ax.set_ylabel("P / (ρ g H)")
        ax.set_title(f"P{k}: {HEIGHTS_MM[k]} mm above the floor", fontsize=10)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, loc="upper right")
    axes[-1].set_xlabel("t √(g/H)")
    fig.tight_layout()
    fig.savefig(args.output)
    print(args.output)


if __name__ == "__main__":
    main()
