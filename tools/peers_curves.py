#!/usr/bin/env python3
"""Rows and summary of tools/peers_curves_3d.sh.

    peers_curves.py isph ROUND SETTING ISPH_OUT SCENE   # one CSV row of an isph run
    peers_curves.py splash ROUND SETTING LINE           # one CSV row of a SPlisHSPlasH run
    peers_curves.py summary CSV -o PNG                  # medians per code and setting, and the plot

Both codes' compression is SPlisHSPlasH's measure, mean(max(rho/rho0 - 1, 0)) over the fluid of
the last frame, and their wall time per simulated second is over steps 2.. (tools/peers_report.py).
The plot draws each code's medians as a curve, wall time per simulated second against
compression, log-log, with the [min, max] of the wall time as error bars.
"""
import argparse
import csv
import statistics
import sys
from collections import defaultdict

from peers_report import isph_fields, parse


def row(round_, code, setting, f):
    # The csv module quotes the setting, and doubles the quotes of a string key inside it
    # (kernel = "wendland_c2").
    csv.writer(sys.stdout, lineterminator="\n").writerow(
        [round_, code, setting, f["steps"], f["iterations_mean"], f["wall_per_sim_second"],
         f["compression_mean"]])


def summary(path, png):
    runs = defaultdict(list)
    with open(path) as fh:
        for r in csv.DictReader(fh):
            runs[(r["code"], r["setting"])].append(r)
    print("%-14s %-34s %6s %6s %9s %22s %12s" % (
        "code", "setting", "runs", "steps", "iter/step", "wall s / sim s", "compression"))
    curves = defaultdict(list)
    for (code, setting), rs in runs.items():
        wall = sorted(float(r["wall_per_sim_second"]) for r in rs)
        comp = statistics.median(float(r["compression_mean"]) for r in rs)
        med = statistics.median(wall)
        print("%-14s %-34s %6d %6s %9s %8.2f [%.2f, %.2f] %12.3e" % (
            code, setting, len(rs), rs[0]["steps"], rs[0]["iterations_mean"],
            med, wall[0], wall[-1], comp))
        curves[code].append((comp, med, wall[0], wall[-1], setting))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 5))
    for code, points in sorted(curves.items()):
        points.sort()
        x = [p[0] for p in points]
        y = [p[1] for p in points]
        err = [[p[1] - p[2] for p in points], [p[3] - p[1] for p in points]]
        ax.errorbar(x, y, yerr=err, marker="o", capsize=3, label=code)
        for p in points:
            ax.annotate(p[4], (p[0], p[1]), fontsize=7, xytext=(4, 4), textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("compression, mean of max(ρ/ρ0 − 1, 0) over the fluid at the end")
    ax.set_ylabel("wall time per simulated second [s]")
    ax.set_title("3D dam break: cost against compression (medians, [min, max])")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    print("plot:", png)


def main():
    p = argparse.ArgumentParser()
    sub = p.add_subparsers(dest="what", required=True)
    a = sub.add_parser("isph")
    a.add_argument("round")
    a.add_argument("setting")
    a.add_argument("out")
    a.add_argument("scene")
    b = sub.add_parser("splash")
    b.add_argument("round")
    b.add_argument("setting")
    b.add_argument("line")
    c = sub.add_parser("summary")
    c.add_argument("csv")
    c.add_argument("-o", dest="png", required=True)
    args = p.parse_args()
    if args.what == "isph":
        row(args.round, "isph", args.setting or "defaults", isph_fields(args.out, args.scene))
    elif args.what == "splash":
        f = parse(args.line)
        row(args.round, f["solver"], args.setting, f)
    else:
        summary(args.csv, args.png)


if __name__ == "__main__":
    sys.exit(main())
