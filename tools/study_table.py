#!/usr/bin/env python3
"""Prints the study.csv of an `isph study` as a Markdown table (for docs/accuracy.md).

    tools/study_table.py OUT/study.csv [--sort KEY]

Columns: the grid keys, the error and its details, wall time, steps, mean PPE iterations and
peak memory; rows sorted by wall time (or by --sort), Pareto points (no other point has both
a lower error and a lower wall time) marked with *. Standard library only.
"""

import argparse
import csv

FIXED = ["id", "error", "wall_seconds", "steps", "ppe_iterations_mean", "peak_bytes", "status"]


def number(text):
    try:
        return float(text)
    except ValueError:
        return None


def pareto(rows):
    """Ids of the rows no other row beats in both error and wall time."""
    ok = [r for r in rows if number(r["error"]) is not None]
    front = set()
    for r in ok:
        e, t = float(r["error"]), float(r["wall_seconds"])
        beaten = any(
            float(o["error"]) <= e and float(o["wall_seconds"]) <= t
            and (float(o["error"]) < e or float(o["wall_seconds"]) < t)
            for o in ok
        )
        if not beaten:
            front.add(r["id"])
    return front


def short(text):
    x = number(text)
    if x is None:
        return text
    if x == int(x) and abs(x) < 1e6:
        return str(int(x))
    return f"{x:.3g}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv")
    parser.add_argument("--sort", default="wall_seconds")
    args = parser.parse_args()
    with open(args.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise SystemExit(f"{args.csv}: no rows")
    names = list(rows[0].keys())
    grid = names[1:names.index("error")]
    details = names[names.index("error") + 1:names.index("wall_seconds")]
    front = pareto(rows)
    rows.sort(key=lambda r: number(r[args.sort]) if number(r[args.sort]) is not None else float("inf"))
    header = grid + ["error"] + details + ["wall s", "steps", "PPE it.", "peak MB", "Pareto"]
    print("| " + " | ".join(f"`{h}`" if h in grid else h for h in header) + " |")
    print("|" + "---|" * len(header))
    for r in rows:
        if r["status"] != "ok":
            cells = [short(r[k]) for k in grid] + [r["status"]] + [""] * (len(header) - len(grid) - 1)
        else:
            cells = (
                [short(r[k]) for k in grid]
                + [f"{float(r['error']):.3g}"]
                + [short(r[k]) for k in details]
                + [f"{float(r['wall_seconds']):.1f}", r["steps"], f"{float(r['ppe_iterations_mean']):.1f}",
                   f"{float(r['peak_bytes']) / 1e6:.0f}", "*" if r["id"] in front else ""]
            )
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
