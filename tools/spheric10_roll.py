#!/usr/bin/env python3
"""Writes scenes/spheric10_roll.csv, the roll of the SPHERIC benchmark 10 tank (docs/bodies.md,
"SPHERIC benchmark 10") as a `table` trajectory: time [s], x, y [m] (zero), angle [deg]; with
--3d, scenes/spheric10_roll_3d.csv, the same roll with a z column (zero) for the 3D tank.

    tools/spheric10_roll.py [--3d] [-o FILE]

The experiment's tank followed a recorded roll, distributed with DualSPHysics's sloshing
example as CaseSloshingMotionData.dat (time and degrees every 0.05 ms). Its steady part is the
sinusoid

    theta(t) = A sin(2 pi (t - t0) / T) + c,   T = 1.6366 s, A = 3.985 deg, c = -0.062 deg,
    t0 = 0.1702 s,

whose crest A + c and trough -A + c are the recording's (+3.92 deg at 0.572 s, -4.05 deg at
7.94 s) and whose delay t0 puts the trough where the recording has it. It starts from rest: until
0.37 s the roll is the polynomial sum_{k=2..7} a_k t^k fitted by least squares to the
recording's samples below and joined to the sinusoid with its value, slope and curvature. The
result lies within 0.02 deg of every sample up to 0.39 s and 0.054 deg at 1.08 s (where the
recording leads the sinusoid by 3.7 ms).
"""

import argparse
import math
import pathlib

import numpy as np

PERIOD, AMPLITUDE, OFFSET, DELAY = 1.6366, 3.985, -0.062, 0.1702
JOIN = 0.37
# (time [s], angle [deg]) read off the recording.
SAMPLES = [
    (0.01, 0.00093567), (0.02, 0.003909444), (0.03, 0.009171466), (0.0393, 0.01633799),
    (0.1506, 0.34515965), (0.16, 0.3996245), (0.17, 0.46318727), (0.18, 0.53279045),
    (0.19, 0.60868422), (0.3506, 2.4634624), (0.36, 2.5798759), (0.37, 2.7008495),
]
POWERS = range(2, 8)


def sinusoid(t, derivative=0):
    """theta and its first and second derivatives in the steady roll."""
    omega = 2 * math.pi / PERIOD
    phase = omega * (t - DELAY)
    return [
        AMPLITUDE * math.sin(phase) + OFFSET,
        AMPLITUDE * omega * math.cos(phase),
        -AMPLITUDE * omega**2 * math.sin(phase),
    ][derivative]


def start_coefficients():
    """a_k of the start from rest: least squares on SAMPLES, joined to the sinusoid at JOIN."""
    fit = np.array([[t**k for k in POWERS] for t, _ in SAMPLES])
    values = np.array([v for _, v in SAMPLES])
    join = np.array([
        [JOIN**k for k in POWERS],
        [k * JOIN ** (k - 1) for k in POWERS],
        [k * (k - 1) * JOIN ** (k - 2) for k in POWERS],
    ])
    n = len(POWERS)
    system = np.zeros((n + 3, n + 3))
    system[:n, :n] = 2 * fit.T @ fit
    system[:n, n:] = join.T
    system[n:, :n] = join
    rhs = np.concatenate([2 * fit.T @ values, [sinusoid(JOIN, d) for d in range(3)]])
    return np.linalg.solve(system, rhs)[:n]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--3d", dest="three", action="store_true", help="with a z column")
    parser.add_argument("-o", "--output", type=pathlib.Path)
    args = parser.parse_args()
    name = "spheric10_roll_3d.csv" if args.three else "spheric10_roll.csv"
    out = args.output or pathlib.Path(__file__).resolve().parent.parent / "scenes" / name
    offsets = "0,0,0" if args.three else "0,0"
    a = start_coefficients()
    rows = ["time,x,y,z,angle" if args.three else "time,x,y,angle"]
    for step in range(0, 1601):
        t = 0.005 * step
        theta = sum(c * t**k for c, k in zip(a, POWERS)) if t < JOIN else sinusoid(t)
        rows.append(f"{t:.3f},{offsets},{theta:.6f}")
    out.write_text("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
