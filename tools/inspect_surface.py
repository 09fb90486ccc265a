#!/usr/bin/env python3
"""Open an isph run's surfaces the way a user would and print what each frame holds.

    python3 tools/inspect_surface.py OUT_DIR

Reads OUT_DIR/surface.xdmf with pyvista (VTK's XDMF reader, the one ParaView uses) as a time
series, and OUT_DIR/surface.h5 with h5py, checks that both agree (times, vertex and cell counts,
cell types, positions, normals), and prints each frame's time, cells, vertices and enclosed
volume (3D). Exits with status 1 on any disagreement.
"""
import sys
from pathlib import Path

import h5py
import numpy as np
import pyvista as pv


def main(out: Path) -> int:
    reader = pv.get_reader(str(out / "surface.xdmf"))
    times = list(reader.time_values)
    problems = []
    with h5py.File(out / "surface.h5", "r") as h5:
        groups = [g for g in sorted(h5.keys()) if h5[g]["cells"].shape[0] > 0]
        if len(groups) != len(times):
            problems.append(f"{len(groups)} HDF5 surfaces but {len(times)} XDMF time steps")
        for name, t in zip(groups, times):
            g = h5[name]
            if abs(g.attrs["time"] - t) > 1e-12 * max(1.0, abs(t)):
                problems.append(f"{name}: HDF5 time {g.attrs['time']} != XDMF time {t}")
            reader.set_active_time_value(t)
            mesh = reader.read()
            if isinstance(mesh, pv.MultiBlock):
                mesh = mesh.combine()
            cells = g["cells"][:]
            per = cells.shape[1]
            if mesh.n_points != g["position"].shape[0] or mesh.n_cells != cells.shape[0]:
                problems.append(f"{name}: pyvista sees {mesh.n_points} points and {mesh.n_cells} cells, "
                                f"HDF5 holds {g['position'].shape[0]} and {cells.shape[0]}")
                continue
            expected = pv.CellType.TRIANGLE if per == 3 else pv.CellType.LINE
            if per == 3 and not np.all(mesh.celltypes == expected):
                problems.append(f"{name}: pyvista's cells are not all triangles")
            if not np.array_equal(np.asarray(mesh.points, dtype=np.float32), g["position"][:]):
                problems.append(f"{name}: positions differ between pyvista and h5py")
            if not np.array_equal(np.asarray(mesh.point_data["normal"], dtype=np.float32), g["normal"][:]):
                problems.append(f"{name}: normals differ between pyvista and h5py")
            line = f"{name}: t = {t:.6f} s, {cells.shape[0]} {'triangles' if per == 3 else 'segments'}, {mesh.n_points} vertices"
            if per == 3:
                p = g["position"][:].astype(float)
                a, b, c = p[cells[:, 0]], p[cells[:, 1]], p[cells[:, 2]]
                line += f", encloses {np.einsum('ij,ij->i', a, np.cross(b, c)).sum() / 6:.6g} m³"
            print(line)
    print(f"{len(times)} surfaces")
    for p in problems:
        print("MISMATCH:", p)
    return 1 if problems else 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    sys.exit(main(Path(sys.argv[1])))
