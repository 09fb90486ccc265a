#!/usr/bin/env bash
# isph's surface reconstruction (`isph surface`) against splashsurf 0.14.1 (MIT, crates.io) on the
# same fluid particles of one frame, at the same kernel support radius, cube size and thread count.
# Each tool runs REPEATS times, alternating (isph, splashsurf, isph, ...); printed: median (min–max)
# wall time of each, the meshes' triangle and vertex counts, enclosed volume (divergence theorem),
# surface area, connected pieces and whether each is closed, and a closing Markdown table.
#
# Usage: tools/splashsurf_compare.sh [RUN_DIR] [FRAME] [options]
#   RUN_DIR    an `isph run` output directory (3D); without it the script makes its own frame: the
#              3D dam break of scenes/dam_break_3d.toml at --spacing, run to --until (kept in
#              WORK/run_dx<DX>_t<T> and reused by later calls; delete that folder to run it anew)
#   FRAME      frame number, or `last` [default: last]
# Options:
#   --threads N      threads of both tools [default: 2]
#   --radius B       kernel support radius in particle spacings dx [default: 3, isph's own for
#                    its quartic kernel, docs/surface.md]: isph `--kernel quartic --radius B`,
#                    splashsurf's cubic spline with compact support B dx (`-l B` at `-r dx/2`;
#                    its README suggests -l 2, i.e. --radius 2)
#   --cube-size C    marching-cubes edge in dx [default: 0.5]: isph `--cube-size C`, splashsurf
#                    `-c 2C` (its cube size is in particle radii)
#   --iso I          isph's iso-value of its density normalised to 1 inside [default: 0.5]
#   --threshold T    splashsurf's surface threshold of its colour field [default: 0.6, its own]
#   --repeats K      timed runs of each tool [default: 3]
#   --warmup W       untimed runs of each tool first (file cache, page faults) [default: 1]
#   --spacing DX     particle spacing of the frame the script makes [default: 0.02 m: 7,500 fluid
#                    particles, 276 steps, 70 s of simulation on 2 idle cores (2.5 min beside a
#                    compile); 0.0125: 30,720 particles; 0.0085: 97,000 particles, 696 steps, an
#                    hour beside other work. At 7,500 particles each tool takes well under 0.1 s
#                    and the times are mostly noise: use 0.0085 for a real comparison]
#   --until T        simulated time of that frame [default: 0.4 s: the surge near the far wall]
#   --work DIR       scratch directory [default: /tmp/isph_splashsurf_compare]
# Environment: ISPH (isph binary; default: target/release/isph, built by `cargo build --release`),
#   SPLASHSURF_ROOT (cargo install root; default ~/.cache/isph-peers/splashsurf).
#
# Conventions (splashsurf 0.14.1's source, splashsurf/src/reconstruct.rs and
# splashsurf_lib/src/kernel.rs): its particle volume is that of a cube of edge 2r
# (kernel::Volume::cube_particle), so a particle of volume dx³ has radius r = dx/2, which is also
# what its README asks for ("the actual radius of the fluid particles", SPlisHSPlasH's dx = 2r);
# its compact support radius is 2·l·r = l·dx, and its cube size c·r = (c/2)·dx. The iso-values
# differ in meaning: isph's c(x) = Σ dx³ D(x − x_i) (each particle its own volume dx³, 1 inside
# the fluid, the surface at 0.5), splashsurf's colour field Σ (m/ρ_j) W(x − x_j) with ρ_j each
# particle's own SPH density (so lone particles and thin sheets count more), the surface at 0.6.
# Times: isph's "reconstruction" is the time it prints per frame (reading the frame from
# particles.h5, the surface with its normals and velocities, writing surface.h5 and the PLY; it
# prints it to 10 ms); splashsurf's is its own "surface reconstruction" timing (reading the .xyz,
# the surface, writing the PLY; no normals); "process" is each whole process, start to exit.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

usage() { sed -n '2,/^set -euo/p' "$ROOT/tools/splashsurf_compare.sh" | sed -e '$d' -e 's/^# \{0,1\}//'; }
die() { echo "splashsurf_compare: error: $*" >&2; exit 1; }

RUN_DIR="" FRAME="last" THREADS=2 RADIUS=3 CUBE=0.5 ISO=0.5 THRESHOLD=0.6 REPEATS=3 WARMUP=1
SPACING=0.02 UNTIL=0.4 WORK=/tmp/isph_splashsurf_compare
POSITIONAL=()
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) usage; exit 0 ;;
    --threads|--radius|--cube-size|--iso|--threshold|--repeats|--warmup|--spacing|--until|--work)
      [ $# -ge 2 ] || die "$1 needs a value"
      case "$1" in
        --threads) THREADS=$2 ;; --radius) RADIUS=$2 ;; --cube-size) CUBE=$2 ;; --iso) ISO=$2 ;;
        --threshold) THRESHOLD=$2 ;; --repeats) REPEATS=$2 ;; --warmup) WARMUP=$2 ;; --spacing) SPACING=$2 ;;
        --until) UNTIL=$2 ;; --work) WORK=$2 ;;
      esac
      shift 2 ;;
    --*) die "unknown option $1 (see --help)" ;;
    *) POSITIONAL+=("$1"); shift ;;
  esac
done
[ ${#POSITIONAL[@]} -le 2 ] || die "at most two arguments, RUN_DIR and FRAME (see --help)"
[ ${#POSITIONAL[@]} -ge 1 ] && RUN_DIR=${POSITIONAL[0]}
[ ${#POSITIONAL[@]} -ge 2 ] && FRAME=${POSITIONAL[1]}
[[ "$FRAME" =~ ^([0-9]+|last)$ ]] || die "FRAME must be a frame number or \`last\`, not \`$FRAME\`"
for v in THREADS REPEATS; do
  [[ "${!v}" =~ ^[1-9][0-9]*$ ]] || die "--$(echo "$v" | tr 'A-Z' 'a-z') must be a positive whole number"
done
[[ "$WARMUP" =~ ^[0-9]+$ ]] || die "--warmup must be a whole number"
for v in RADIUS CUBE ISO THRESHOLD SPACING UNTIL; do
  [[ "${!v}" =~ ^[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?$ ]] || die "$v = ${!v} is not a number"
done
if [ -n "$RUN_DIR" ]; then
  [ -f "$RUN_DIR/particles.h5" ] || die "$RUN_DIR is not an isph run directory (no particles.h5)"
  RUN_DIR="$(cd "$RUN_DIR" && pwd)"
fi
mkdir -p "$WORK"
WORK="$(cd "$WORK" && pwd)"

# --- tools --------------------------------------------------------------------------------------
echo "== setup (tools/setup.sh: h5py, numpy)"
./tools/setup.sh
python3 -c "import h5py, numpy" 2>/dev/null || die "h5py and numpy are still missing after tools/setup.sh"

if [ -n "${ISPH:-}" ]; then
  [ -x "$ISPH" ] || die "ISPH=$ISPH is not an executable"
else
  echo "== isph: cargo build --release"
  cargo build --release -q || die "cargo build --release failed"
  ISPH="$ROOT/target/release/isph"
fi
"$ISPH" surface --help >/dev/null 2>&1 || die "$ISPH has no \`surface\` command (an old build?)"

SPLASHSURF_ROOT=${SPLASHSURF_ROOT:-$HOME/.cache/isph-peers/splashsurf}
SPLASH="$SPLASHSURF_ROOT/bin/splashsurf"
if ! { [ -x "$SPLASH" ] && "$SPLASH" --version 2>/dev/null | grep -qx 'splashsurf 0.14.1'; }; then
  echo "== splashsurf 0.14.1: cargo install into $SPLASHSURF_ROOT (a few minutes, once)"
  start=$(date +%s)
  cargo install splashsurf --version 0.14.1 --locked --root "$SPLASHSURF_ROOT" \
    || die "cargo install splashsurf --version 0.14.1 failed"
  echo "   installed in $(( $(date +%s) - start )) s"
fi
SPLASH_VERSION=$("$SPLASH" --version)

# --- the frame ----------------------------------------------------------------------------------
if [ -z "$RUN_DIR" ]; then
  RUN_DIR="$WORK/run_dx${SPACING}_t${UNTIL}"
  SCENE_LABEL="scenes/dam_break_3d.toml at spacing $SPACING m"
  if [ -f "$RUN_DIR/.complete" ]; then
    echo "== frame: reusing $RUN_DIR (delete it to simulate anew)"
  else
    SCENE="$WORK/dam_break_3d_dx$SPACING.toml"
    sed -e "s/^spacing = [0-9.e-]*/spacing = $SPACING/" \
        -e "s/^output_interval = [0-9.e-]*/output_interval = $UNTIL/" \
        scenes/dam_break_3d.toml > "$SCENE"
    grep -q "^spacing = $SPACING " "$SCENE" && grep -q "^output_interval = $UNTIL " "$SCENE" \
      || die "could not set spacing/output_interval in $SCENE (has scenes/dam_break_3d.toml changed?)"
    echo "== frame: isph run $SCENE --until $UNTIL --threads $THREADS (log: $WORK/run.log) ..."
    start=$(date +%s)
    "$ISPH" run "$SCENE" --until "$UNTIL" --out "$RUN_DIR" --threads "$THREADS" --overwrite -q \
      > "$WORK/run.log" 2>&1 || { cat "$WORK/run.log" >&2; die "isph run failed"; }
    touch "$RUN_DIR/.complete"
    echo "   simulated in $(( $(date +%s) - start )) s: $(head -1 "$WORK/run.log")"
  fi
else
  SCENE_LABEL="$RUN_DIR"
fi

XYZ="$WORK/particles.xyz"
INFO=$(python3 tools/surface_compare.py export "$RUN_DIR" "$FRAME" "$XYZ")
eval "$(echo "$INFO" | tr ' ' '\n' | sed -n 's/^\(frame\|time\|particles\|spacing\)=\(.*\)$/P_\1=\2/p')"
echo "== frame $P_frame (t = $P_time s) of $RUN_DIR: $P_particles fluid particles, dx = $P_spacing m -> $XYZ"
[ "$P_particles" -gt 0 ] || die "frame $P_frame has no fluid particles"

calc() { python3 -c "print(repr(float($1)))"; }
R=$(calc "$P_spacing / 2")            # splashsurf's particle radius: (2r)^3 = dx^3
C_SPLASH=$(calc "2 * $CUBE")          # cube size in particle radii
SUPPORT=$(calc "$RADIUS * $P_spacing")

ISPH_OUT="$WORK/isph_surface"
SPLASH_OUT="$WORK/splashsurf"
mkdir -p "$SPLASH_OUT"
ISPH_PLY="$ISPH_OUT/surface/frame_$(printf %06d "$P_frame").ply"
SPLASH_PLY="$SPLASH_OUT/frame_$(printf %06d "$P_frame").ply"
ISPH_CMD=("$ISPH" surface "$RUN_DIR" --frames "$P_frame" --kernel quartic --radius "$RADIUS"
          --cube-size "$CUBE" --iso "$ISO" --threads "$THREADS" --out "$ISPH_OUT" --overwrite)
SPLASH_CMD=("$SPLASH" reconstruct "$XYZ" -r "$R" -l "$RADIUS" -c "$C_SPLASH" -t "$THRESHOLD"
            -n "$THREADS" -o "$SPLASH_PLY")

now() { date +%s.%N; }
for i in $(seq 1 "$WARMUP"); do
  echo "== warm-up $i (untimed)"
  RAYON_NUM_THREADS=$THREADS "${ISPH_CMD[@]}" > "$WORK/isph_warmup.log" 2>&1 \
    || { cat "$WORK/isph_warmup.log" >&2; die "isph surface failed"; }
  RAYON_NUM_THREADS=$THREADS "${SPLASH_CMD[@]}" > "$WORK/splashsurf_warmup.log" 2>&1 \
    || { cat "$WORK/splashsurf_warmup.log" >&2; die "splashsurf reconstruct failed"; }
done
LOAD_BEFORE=$(cut -d' ' -f1-3 /proc/loadavg)
ISPH_RECON="" ISPH_PROC="" SPLASH_RECON="" SPLASH_CORE="" SPLASH_PROC=""
echo "== $REPEATS runs each on $THREADS threads, alternating; kernel support $SUPPORT m, cube $(calc "$CUBE * $P_spacing") m"
for i in $(seq 1 "$REPEATS"); do
  t0=$(now)
  RAYON_NUM_THREADS=$THREADS "${ISPH_CMD[@]}" > "$WORK/isph_$i.log" 2>&1 \
    || { cat "$WORK/isph_$i.log" >&2; die "isph surface failed"; }
  t1=$(now)
  line=$(grep "^frame $P_frame " "$WORK/isph_$i.log" || true)
  recon=$(echo "$line" | sed -n 's/.*, \([0-9.]*\) s$/\1/p')
  [ -n "$recon" ] || die "isph printed no time for frame $P_frame; see $WORK/isph_$i.log"
  proc=$(calc "$t1 - $t0")
  ISPH_RECON+="$recon " ISPH_PROC+="$proc "
  echo "   isph       run $i: reconstruction $recon s, process $(printf %.3f "$proc") s"

  t0=$(now)
  RAYON_NUM_THREADS=$THREADS "${SPLASH_CMD[@]}" > "$WORK/splashsurf_$i.log" 2>&1 \
    || { cat "$WORK/splashsurf_$i.log" >&2; die "splashsurf reconstruct failed"; }
  t1=$(now)
  eval "$(python3 tools/surface_compare.py splash-times "$WORK/splashsurf_$i.log")"
  proc=$(calc "$t1 - $t0")
  SPLASH_RECON+="$(calc "$total_ms / 1000") " SPLASH_CORE+="$(calc "$core_ms / 1000") " SPLASH_PROC+="$proc "
  echo "   splashsurf run $i: reconstruction $(printf %.3f "$(calc "$total_ms / 1000")") s (without reading and writing $(printf %.3f "$(calc "$core_ms / 1000")") s), process $(printf %.3f "$proc") s"
done
LOAD_AFTER=$(cut -d' ' -f1-3 /proc/loadavg)
echo "   load average (1, 5, 15 min) before the timed runs: $LOAD_BEFORE, after: $LOAD_AFTER"
BUSY=$(ps -eo pcpu=,comm= --sort=-pcpu | awk '$1 > 20 {printf "%s%s (%s%%)", sep, $2, $1; sep=", "}')
[ -z "$BUSY" ] || echo "   warning: other processes busy now: $BUSY; the times may be disturbed"

echo "== meshes"
ISPH_MESH=$(python3 tools/surface_compare.py mesh "$ISPH_PLY")
SPLASH_MESH=$(python3 tools/surface_compare.py mesh "$SPLASH_PLY")
echo "   isph       $ISPH_PLY: $ISPH_MESH"
echo "   splashsurf $SPLASH_PLY: $SPLASH_MESH"
echo "   the particles' own volume N·dx³ = $(python3 -c "print(f'{$P_particles * $P_spacing**3:.6e}')") m³"

RESULTS="$WORK/results.txt"
{
  echo "scene=$SCENE_LABEL"
  echo "frame=$P_frame"
  echo "time=$P_time"
  echo "particles=$P_particles"
  echo "spacing=$P_spacing"
  echo "radius=$RADIUS"
  echo "cube=$CUBE"
  echo "threads=$THREADS"
  echo "repeats=$REPEATS"
  echo "warmup=$WARMUP"
  echo "load=$LOAD_BEFORE before, $LOAD_AFTER after"
  echo "machine=$(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores"
  echo "splash_version=$SPLASH_VERSION"
  echo "isph_cmd=isph surface RUN --frames $P_frame --kernel quartic --radius $RADIUS --cube-size $CUBE --iso $ISO --threads $THREADS"
  echo "splash_cmd=splashsurf reconstruct frame.xyz -r $R -l $RADIUS -c $C_SPLASH -t $THRESHOLD -n $THREADS -o frame.ply"
  echo "isph_settings=quartic b=$RADIUS dx, iso $ISO"
  echo "splash_settings=cubic spline h=$RADIUS dx, r=dx/2, t=$THRESHOLD"
  echo "isph_recon=$ISPH_RECON"
  echo "isph_process=$ISPH_PROC"
  echo "splash_recon=$SPLASH_RECON"
  echo "splash_core=$SPLASH_CORE"
  echo "splash_process=$SPLASH_PROC"
  echo "isph_mesh=$ISPH_MESH"
  echo "splash_mesh=$SPLASH_MESH"
} > "$RESULTS"
echo
python3 tools/surface_compare.py report "$RESULTS"
echo
echo "(raw numbers: $RESULTS; logs and meshes: $WORK)"
