#!/usr/bin/env python3
"""Runs a scene with each stabilisation fix switched on and off, and the α sweep of Eq. (6).

    python3 tools/ablation.py [--isph target/release/isph] [--out out/ablation] [--until T]
                              [--only NAME,...] SCENE.toml [SCENE.toml ...]

For every scene it runs these variants (each a copy of the scene with one setting changed):

    default        the scene as it is
    alpha=A        [solver] alpha = A for A in 0, 0.001, 0.01, 0.1, 0.5
    no-shifting           [effects.shifting] enabled = false
    no-kernel_correction  [effects.kernel_correction] enabled = false
    no-les                [effects.les] enabled = false
    mirror-walls          [walls] ghost_pressure = "mirror" (a simpler wall: P_b = P_i)

and prints one Markdown table row per variant, also written to OUT/ablation.md and OUT/ablation.csv:

    pressure noise   rms of P − ρ0 g (H − y) over fluid particles deeper than 15% of H in the last
                     frame, over ρ0 g H; only for a scene whose name starts with `hydrostatic`
    density error    mean and max over the steps of stats.csv `density_error`
    disorder         stats.csv `disorder` at the end and its max over the run
    penetrations     max over the steps of stats.csv `penetrations`
    max speed        stats.csv `max_speed` at the end
    PPE iterations   mean over the steps
    wall time        seconds for the whole run (stats.csv `wall_seconds` of the last step)
    status           `ok`, or the error isph stopped with

A variant whose output already holds a finished run (its `done` marker) is not run again.
"""

import argparse
import csv
import math
import subprocess
import sys
import tomllib
from pathlib import Path

import h5py
import numpy as np

ALPHAS = [0.0, 0.001, 0.01, 0.1, 0.5]


def variants(scene: dict) -> dict:
    """The variants' scenes, by name."""
    out = {"default": scene}
    for a in ALPHAS:
        out[f"alpha={a:g}"] = with_key(scene, ["solver", "alpha"], a)
    for effect in ["shifting", "kernel_correction", "les"]:
        out[f"no-{effect}"] = with_key(scene, ["effects", effect], {"enabled": False})
    out["mirror-walls"] = with_key(scene, ["walls", "ghost_pressure"], "mirror")
    return out


def with_key(scene: dict, path: list, value) -> dict:
    """A deep copy of `scene` with the key at `path` set to `value` (tables created as needed)."""
    import copy

    s = copy.deepcopy(scene)
    t = s
    for k in path[:-1]:
        t = t.setdefault(k, {})
    t[path[-1]] = value
    return s


def toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {v!r} as TOML")


def toml_text(table: dict, prefix: str = "") -> str:
    """TOML for a scene: scalars first, then sub-tables, then arrays of tables."""
    lines, tables, arrays = [], [], []
    for k, v in table.items():
        if isinstance(v, dict):
            tables.append((k, v))
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            arrays.append((k, v))
        else:
            lines.append(f"{k} = {toml_value(v)}")
    text = "\n".join(lines) + ("\n" if lines else "")
    for k, v in tables:
        name = f"{prefix}{k}"
        text += f"\n[{name}]\n" + toml_text(v, name + ".")
    for k, items in arrays:
        for item in items:
            text += f"\n[[{prefix}{k}]]\n" + toml_text(item, f"{prefix}{k}.")
    return text


def stats(out: Path) -> dict:
    with open(out / "stats.csv") as f:
        rows = list(csv.DictReader(f))
    col = lambda name: np.array([float(r[name]) for r in rows])
    if not rows:
        return {}
    return {
        "steps": len(rows),
        "t_end": col("time")[-1],
        "density_mean": np.nanmean(col("density_error")),
        "density_max": np.nanmax(col("density_error")),
        "disorder_end": col("disorder")[-1],
        "disorder_max": np.nanmax(col("disorder")),
        "penetrations": int(col("penetrations").max()),
        "max_speed_end": col("max_speed")[-1],
        "ppe_iterations": col("ppe_iterations").mean(),
        "wall_s": col("wall_seconds")[-1],
    }


def hydrostatic_noise(out: Path, scene: dict) -> float:
    """rms(P − ρ0 g (H − y)) / (ρ0 g H) over fluid deeper than 15% of H in the last frame."""
    g = abs(scene["simulation"]["gravity"][-1])
    rho0 = scene["fluid"][0]["density"]
    with h5py.File(out / "particles.h5", "r") as f:
        frame = f[sorted(f, key=lambda k: f[k].attrs["time"])[-1]]
        kind, pos, p = frame["kind"][:], frame["position"][:], frame["pressure"][:]
    fluid = kind == 0
    up = len(scene["simulation"]["gravity"]) - 1  # positions are stored with 3 components
    y = pos[fluid, up]
    spacing = scene["simulation"]["spacing"]
    surface = y.max() + 0.5 * spacing
    depth = surface - y
    deep = depth > 0.15 * surface
    err = p[fluid][deep] - rho0 * g * depth[deep]
    return math.sqrt(np.mean(err**2)) / (rho0 * g * surface)


def run(isph: str, scene: dict, out: Path, until) -> str:
    if (out / "done").exists():
        return (out / "done").read_text().strip()
    out.mkdir(parents=True, exist_ok=True)
    path = out / "scene.toml"
    path.write_text(toml_text(scene))
    cmd = [isph, "run", str(path), "--out", str(out / "run"), "--overwrite", "-q"]
    if until is not None:
        cmd += ["--until", str(until)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    status = "ok" if r.returncode == 0 else r.stderr.strip().splitlines()[-1][:120]
    (out / "done").write_text(status + "\n")
    return status


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="+", type=Path)
    ap.add_argument("--isph", default="target/release/isph")
    ap.add_argument("--out", type=Path, default=Path("out/ablation"))
    ap.add_argument("--until", type=float)
    ap.add_argument("--only", help="comma-separated variant names")
    args = ap.parse_args()
    header = ("| scene | variant | pressure noise | density error mean / max | disorder end / max "
              "| penetrations | max speed end [m/s] | PPE it/step | wall [s] | status |")
    table = [header, "|" + "---|" * (header.count("|") - 1)]
    records = []
    for scene_path in args.scenes:
        with open(scene_path, "rb") as f:
            scene = tomllib.load(f)
        for name, variant in variants(scene).items():
            if args.only and name not in args.only.split(","):
                continue
            out = args.out / scene_path.stem / name.replace("=", "_")
            status = run(args.isph, variant, out, args.until)
            s = stats(out / "run")
            noise = float("nan")
            if scene_path.stem.startswith("hydrostatic") and status == "ok":
                noise = hydrostatic_noise(out / "run", variant)
            rec = {"scene": scene_path.stem, "variant": name, "pressure_noise": noise, **s, "status": status}
            records.append(rec)
            row = (f"| {scene_path.stem} | {name} | "
                   + ("–" if math.isnan(noise) else f"{100 * noise:.3f}%")
                   + f" | {100 * s.get('density_mean', math.nan):.3f}% / {100 * s.get('density_max', math.nan):.2f}%"
                   + f" | {100 * s.get('disorder_end', math.nan):.1f}% / {100 * s.get('disorder_max', math.nan):.1f}%"
                   + f" | {s.get('penetrations', '–')} | {s.get('max_speed_end', math.nan):.3g}"
                   + f" | {s.get('ppe_iterations', math.nan):.1f} | {s.get('wall_s', math.nan):.0f} | {status} |")
            table.append(row)
            print(row, flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "ablation.md").write_text("\n".join(table) + "\n")
    keys = sorted({k for r in records for k in r}, key=lambda k: list(records[0]).index(k) if k in records[0] else 99)
    with open(args.out / "ablation.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(records)
    return 0


if __name__ == "__main__":
    sys.exit(main())
