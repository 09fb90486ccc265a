#!/usr/bin/env python3
"""Open an isph run the way a user would and print what each frame holds.

    python3 tools/inspect_run.py OUT_DIR

Reads OUT_DIR/particles.xdmf with pyvista (VTK's XDMF reader, the one ParaView uses) as a
time series, and OUT_DIR/particles.h5 with h5py, checks that both agree (frame times, particle
counts, every field), and prints each frame's time, particle count and field ranges.
Exits with status 1 on any disagreement.
"""
import sys
from pathlib import Path

import h5py
import numpy as np
import pyvista as pv

FIELDS = ["velocity", "pressure", "density", "kind", "fluid", "free_surface", "body", "id"]


def main(out: Path) -> int:
    reader = pv.get_reader(str(out / "particles.xdmf"))
    times = list(reader.time_values)
    problems = []
    with h5py.File(out / "particles.h5", "r") as h5:
        groups = sorted(h5.keys())
        if len(groups) != len(times):
            problems.append(f"{len(groups)} HDF5 frames but {len(times)} XDMF time steps")
        for k, (name, t) in enumerate(zip(groups, times)):
            g = h5[name]
            if abs(g.attrs["time"] - t) > 1e-12 * max(1.0, abs(t)):
                problems.append(f"{name}: HDF5 time {g.attrs['time']} != XDMF time {t}")
            reader.set_active_time_value(t)
            mesh = reader.read()
            if isinstance(mesh, pv.MultiBlock):
                mesh = mesh.combine()
            n = mesh.n_points
            if n != g["position"].shape[0]:
                problems.append(f"{name}: pyvista sees {n} points, HDF5 holds {g['position'].shape[0]}")
            if not np.array_equal(np.asarray(mesh.points, dtype=float), g["position"][:]):
                problems.append(f"{name}: positions differ between pyvista and h5py")
            ranges = []
            for field in FIELDS:
                a = np.asarray(mesh.point_data[field])
                if not np.array_equal(a.astype(float), g[field][:].astype(float)):
                    problems.append(f"{name}: field {field} differs between pyvista and h5py")
                v = np.linalg.norm(a, axis=1) if a.ndim == 2 else a
                ranges.append(f"{field} [{v.min():.4g}, {v.max():.4g}]")
            print(f"frame {k}: t = {t:.6f} s, step {g.attrs['step']}, {n} particles, " + ", ".join(ranges))
    print(f"{len(times)} frames")
    for p in problems:
        print("MISMATCH:", p)
    return 1 if problems else 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    sys.exit(main(Path(sys.argv[1])))
