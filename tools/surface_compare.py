#!/usr/bin/env python3
"""The Python half of tools/splashsurf_compare.sh (numpy and h5py only).

Subcommands:
  export RUN_DIR FRAME OUT.xyz
      Writes the fluid particles (kind 0) of frame FRAME (a number or `last`) of RUN_DIR's
      particles.h5 as raw little-endian f32 x y z triples (splashsurf's `.xyz`), and prints
      `frame=K time=T particles=N spacing=DX dimensions=D` on one line.
  mesh FILE.ply
      Reads a binary little-endian PLY triangle mesh (isph's or splashsurf's) and prints
      `triangles=.. vertices=.. volume=.. area=.. components=.. closed=yes|no boundary_edges=..
      nonmanifold_edges=..` (volume by the divergence theorem; closed: every edge in exactly two
      triangles).
  splash-times LOG
      Prints splashsurf's own timings from its log: `total_ms=..` (its "surface reconstruction"
      stage: reading the particles, reconstructing, writing the mesh) and `core_ms=..` (the
      reconstruction alone: "surface reconstruction subdomain-grid" or
      "reconstruct_surface_global").
  report RESULTS
      Prints the closing table from the key=value lines the shell script collected.
"""
import re
import statistics
import sys

import numpy as np


# --- particles --------------------------------------------------------------------------------

def export(run_dir, frame, out):
    import h5py

    with h5py.File(f"{run_dir}/particles.h5", "r") as f:
        dims = int(f.attrs["dimensions"])
        dx = float(f.attrs["spacing"])
        frames = sorted(k for k in f.keys() if re.fullmatch(r"frame_\d+", k))
        if not frames:
            sys.exit(f"error: {run_dir}/particles.h5 holds no frames")
        if frame == "last":
            name = frames[-1]
        else:
            name = f"frame_{int(frame):06d}"
            if name not in f:
                sys.exit(f"error: {run_dir}/particles.h5 has no {name} (it has {frames[0]} to {frames[-1]})")
        g = f[name]
        kind = g["kind"][:]
        pos = g["position"][:][kind == 0]
        time = float(g.attrs.get("time", float("nan")))
    if dims != 3:
        sys.exit(f"error: the run is {dims}D; splashsurf reconstructs 3D particles only")
    pos.astype("<f4").tofile(out)
    print(f"frame={int(name[6:])} time={time:g} particles={len(pos)} spacing={dx!r} dimensions={dims}")


# --- meshes -----------------------------------------------------------------------------------

PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "<i2", "int16": "<i2", "ushort": "<u2", "uint16": "<u2",
    "int": "<i4", "int32": "<i4", "uint": "<u4", "uint32": "<u4",
    "float": "<f4", "float32": "<f4", "double": "<f8", "float64": "<f8",
}


def read_ply(path):
    """(vertices n×3 f64, triangles m×3 i64) of a binary little-endian PLY whose vertex element
    has only scalar properties and whose faces are all triangles."""
    with open(path, "rb") as fh:
        data = fh.read()
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply") or end < 0:
        sys.exit(f"error: {path} is not a PLY file")
    header = data[:end].decode("ascii").splitlines()
    body = memoryview(data)[end + len("end_header\n"):]
    if "format binary_little_endian 1.0" not in header:
        sys.exit(f"error: {path}: only binary little-endian PLY is read here")
    elements = []  # [name, count, [(prop name, dtype or ('list', count dtype, item dtype))]]
    for line in header:
        w = line.split()
        if not w:
            continue
        if w[0] == "element":
            elements.append([w[1], int(w[2]), []])
        elif w[0] == "property":
            if w[1] == "list":
                elements[-1][2].append((w[4], ("list", PLY_TYPES[w[2]], PLY_TYPES[w[3]])))
            else:
                elements[-1][2].append((w[2], PLY_TYPES[w[1]]))
    offset = 0
    verts = tris = None
    for name, count, props in elements:
        if all(not isinstance(t, tuple) for _, t in props):
            dt = np.dtype([(p, t) for p, t in props])
            arr = np.frombuffer(body, dtype=dt, count=count, offset=offset)
            offset += dt.itemsize * count
            if name == "vertex":
                verts = np.stack([arr["x"], arr["y"], arr["z"]], axis=1).astype(np.float64)
        elif name == "face" and len(props) == 1:
            _, (_, ct, it) = props[0]
            # Every face a triangle: fixed-size records (count, i0, i1, i2).
            dt = np.dtype([("n", ct), ("i", it, (3,))])
            arr = np.frombuffer(body, dtype=dt, count=count, offset=offset)
            if count and not np.all(arr["n"] == 3):
                sys.exit(f"error: {path}: not every face is a triangle")
            offset += dt.itemsize * count
            tris = arr["i"].astype(np.int64)
        else:
            sys.exit(f"error: {path}: element {name} has a layout this reader does not handle")
    if verts is None or tris is None:
        sys.exit(f"error: {path}: no vertex or face element")
    return verts, tris


def enclosed_volume(verts, tris):
    """Σ over triangles of a·(b×c)/6 (the divergence theorem): the volume a closed,
    consistently outward-oriented mesh encloses."""
    a, b, c = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def edge_counts(tris):
    """(edges in exactly one triangle, edges in more than two): a mesh is closed when every
    undirected edge lies in exactly two triangles."""
    if len(tris) == 0:
        return 0, 0
    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    e.sort(axis=1)
    key = e[:, 0] * (int(e.max()) + 1) + e[:, 1]
    _, counts = np.unique(key, return_counts=True)
    return int((counts == 1).sum()), int((counts > 2).sum())


def area(verts, tris):
    a, b, c = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    return float(np.linalg.norm(np.cross(b - a, c - a), axis=1).sum() / 2.0)


def components(nverts, tris):
    """The number of connected pieces of the mesh (vertices joined by triangles; vertices in no
    triangle are not counted): label propagation with pointer jumping."""
    if len(tris) == 0:
        return 0
    label = np.arange(nverts)
    while True:
        low = label[tris].min(axis=1)
        new = label.copy()
        for k in range(3):
            np.minimum.at(new, tris[:, k], low)
        new = new[new]
        while True:  # pointer jumping: follow each label to its root
            nxt = new[new]
            if np.array_equal(nxt, new):
                break
            new = nxt
        if np.array_equal(new, label):
            break
        label = new
    used = np.unique(tris)
    return int(np.unique(label[used]).size)


def mesh(path):
    verts, tris = read_ply(path)
    boundary, nonmanifold = edge_counts(tris)
    closed = "yes" if boundary == 0 and nonmanifold == 0 else "no"
    print(
        f"triangles={len(tris)} vertices={len(verts)} volume={enclosed_volume(verts, tris):.6e} "
        f"area={area(verts, tris):.6e} components={components(len(verts), tris)} "
        f"closed={closed} boundary_edges={boundary} nonmanifold_edges={nonmanifold}"
    )


# --- splashsurf's timings ---------------------------------------------------------------------

def splash_times(log):
    text = open(log, encoding="utf-8", errors="replace").read()

    def stage(name):
        m = re.search(r"\]\s*" + re.escape(name) + r": [0-9.≈]+%, ([0-9.]+)ms avg", text)
        return m and float(m.group(1))

    total = stage("surface reconstruction")
    core = stage("surface reconstruction subdomain-grid") or stage("reconstruct_surface_global")
    if total is None or core is None:
        sys.exit(f"error: no timings found in splashsurf's log {log}")
    print(f"total_ms={total} core_ms={core}")


# --- the closing table ------------------------------------------------------------------------

def report(path):
    kv = {}
    for line in open(path, encoding="utf-8"):
        if "=" in line:
            k, v = line.rstrip("\n").split("=", 1)
            kv[k] = v

    def times(key, digits=3):
        xs = [float(x) for x in kv.get(key, "").split()]
        if not xs:
            return "-"
        return f"{statistics.median(xs):.{digits}f} ({min(xs):.{digits}f}–{max(xs):.{digits}f})"

    n = int(kv["particles"])
    dx = float(kv["spacing"])
    fluid = n * dx**3
    print(f"# {kv['scene']}, frame {kv['frame']} (t = {kv['time']} s): {n} fluid particles, dx = {dx} m, "
          f"N·dx³ = {fluid:.6e} m³")
    print(f"# kernel support {kv['radius']} dx = {float(kv['radius']) * dx:g} m, cube {kv['cube']} dx = "
          f"{float(kv['cube']) * dx:g} m, {kv['threads']} threads, {kv['repeats']} timed runs each, alternating, "
          f"after {kv.get('warmup', 0)} untimed; times: median (min–max) in s")
    print(f"# isph: {kv['isph_cmd']}")
    print(f"# splashsurf {kv['splash_version']}: {kv['splash_cmd']}")
    print(f"# machine: {kv['machine']}; load average (1, 5, 15 min): {kv.get('load', '?')}")
    cols = ["tool", "settings", "recon_s", "process_s", "triangles", "vertices", "pieces",
            "volume_m3", "volume/N·dx³", "area_m2", "closed"]
    rows = []
    for tool, label in (("isph", "isph"), ("splash", "splashsurf")):
        m = dict(w.split("=", 1) for w in kv[f"{tool}_mesh"].split())
        vol = float(m["volume"])
        closed = m["closed"] if m["closed"] == "yes" else \
            f"no ({m['boundary_edges']} open, {m['nonmanifold_edges']} non-manifold edges)"
        # isph prints its time to 10 ms.
        recon = times(f"{tool}_recon", 2 if tool == "isph" else 3)
        rows.append([label, kv[f"{tool}_settings"], recon, times(f"{tool}_process"),
                     m["triangles"], m["vertices"], m["components"], f"{vol:.6e}", f"{vol / fluid:.4f}",
                     f"{float(m['area']):.4e}", closed])
    if kv.get("splash_core"):
        print(f"# splashsurf's reconstruction alone (no reading, no writing): {times('splash_core')} s")
    print("| " + " | ".join(cols) + " |")
    print("|" + "|".join("---" for _ in cols) + "|")
    for r in rows:
        print("| " + " | ".join(r) + " |")


def main(argv):
    usage = __doc__.split("\n\n")[1]
    if len(argv) < 2:
        sys.exit(usage)
    cmd, args = argv[1], argv[2:]
    if cmd == "export" and len(args) == 3:
        export(*args)
    elif cmd == "mesh" and len(args) == 1:
        mesh(args[0])
    elif cmd == "splash-times" and len(args) == 1:
        splash_times(args[0])
    elif cmd == "report" and len(args) == 1:
        report(args[0])
    else:
        sys.exit(usage)


if __name__ == "__main__":
    main(sys.argv)
