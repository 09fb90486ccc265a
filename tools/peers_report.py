#!/usr/bin/env python3
"""The isph side of tools/peers_dambreak_3d.sh and the side-by-side table.

    peers_report.py ISPH_OUT SCENE SPLASH_LINE...

ISPH_OUT is the output directory of `isph run`, SCENE its scene file, each SPLASH_LINE the
`peer=splishsplash key=value ...` line of tools/splishsplash_dambreak_3d.py for one solver.
Prints the isph line in the same form, then the table and the ratios of wall time per
simulated second.

isph's numbers, measured as the SPlisHSPlasH driver measures its own:
  - wall time from the end of step 1 to the end of the last step (stats.csv `wall_seconds`), over
    the simulated time of those steps;
  - density_error: stats.csv's column (mean |rho/rho0 - 1| over the fluid particles with no
    free-surface particle in their kernel support), at the last step and its mean over the run;
  - compression_mean: mean(max(rho/rho0 - 1, 0)) over all fluid particles of the last frame
    (summation density at the start of the last step), SPlisHSPlasH's measure.
"""
import csv
import sys
import tomllib

import h5py
import numpy as np


def isph_fields(out, scene_path):
    with open(f"{out}/stats.csv") as fh:
        rows = list(csv.DictReader(fh))
    col = lambda name: np.array([float(r[name]) for r in rows])
    wall, time, dt = col("wall_seconds"), col("time"), col("dt")
    sim_time = time[-1] - time[0]
    with open(scene_path, "rb") as fh:
        rho0 = tomllib.load(fh)["fluid"][0]["density"]
    with h5py.File(f"{out}/particles.h5", "r") as f:
        last = f[sorted(k for k in f.keys() if k.startswith("frame_"))[-1]]
        fluid = last["kind"][:] == 0
        ratio = last["density"][:][fluid] / rho0 - 1.0
        n, boundary = int(fluid.sum()), int((~fluid).sum())
    steps = len(rows) - 1
    error = col("density_error")
    return {
        "solver": "BiCGSTAB+multigrid",
        "fluid": n,
        "boundary": boundary,
        "steps": steps,
        "sim_time": "%.4f" % sim_time,
        "wall": "%.3f" % (wall[-1] - wall[0]),
        "wall_per_sim_second": "%.2f" % ((wall[-1] - wall[0]) / sim_time),
        "us_per_fluid_particle_step": "%.3f" % ((wall[-1] - wall[0]) / steps / n * 1e6),
        "dt_mean": "%.3e" % dt.mean(),
        "iterations_mean": "%.2f" % col("ppe_iterations").mean(),
        "compression_mean": "%.3e" % np.maximum(ratio, 0.0).mean(),
        "density_error_last": "%.3e" % error[-1],
        "density_error_mean": "%.3e" % np.nanmean(error),
        "penetrations_last": int(col("penetrations")[-1]),
    }


def parse(line):
    return dict(kv.split("=", 1) for kv in line.split()[1:])


def main():
    out, scene, splash_lines = sys.argv[1], sys.argv[2], sys.argv[3:]
    isph = {k: str(v) for k, v in isph_fields(out, scene).items()}
    print("peer=isph " + " ".join("%s=%s" % kv for kv in isph.items()))
    for line in splash_lines:
        print(line)
    print()
    columns = [
        ("fluid", "fluid"), ("boundary", "boundary"), ("steps", "steps"),
        ("dt_mean", "mean dt [s]"), ("iterations_mean", "iter/step"),
        ("wall_per_sim_second", "wall s / sim s"),
        ("us_per_fluid_particle_step", "us/fluid/step"),
        ("compression_mean", "compression"), ("density_error_last", "isph dens. err"),
    ]
    codes = [("isph " + isph["solver"], isph)]
    codes += [("SPlisHSPlasH " + f["solver"], f) for f in map(parse, splash_lines)]
    print("%-30s" % "code" + "".join("%16s" % title for _, title in columns))
    for name, fields in codes:
        print("%-30s" % name + "".join("%16s" % fields.get(k, "-") for k, _ in columns))
    print()
    for name, fields in codes[1:]:
        ratio = float(isph["wall_per_sim_second"]) / float(fields["wall_per_sim_second"])
        print("wall time per simulated second, isph / %s: %.2f" % (name, ratio))


if __name__ == "__main__":
    main()
