#!/usr/bin/env bash
# The 3D dam break of scenes/dam_break_3d.toml (tank 1.0 x 0.4 x 0.6 m, water block
# 0.3 x 0.4 x 0.5 m) in isph and in SPlisHSPlasH (pysplishsplash 2.19.0 from PyPI, headless),
# one after the other, at the same particle spacing, to the same simulated time, on the same
# number of threads. Prints wall time per simulated second of each, their ratio, and the density
# error each reached (see tools/peers_report.py and tools/splishsplash_dambreak_3d.py for what
# is measured and how).
#
# Usage: tools/peers_dambreak_3d.sh [SPACING=0.02] [UNTIL=0.3] [THREADS=2] [SOLVERS="DFSPH IISPH"]
#   SPACING  particle spacing dx [m] (SPlisHSPlasH radius dx/2); 0.02 -> 7,500 fluid particles
#   UNTIL    simulated seconds
#   SOLVERS  SPlisHSPlasH's implicit pressure solvers to run, each in turn: DFSPH, IISPH
# Environment: ISPH (isph binary, default target/release/isph, built if missing), WORK (scratch
# directory, default /tmp/isph_peers_dambreak_3d), SPLASH_VENV (default /tmp/peers_splash_venv),
# MAXERROR (SPlisHSPlasH's density tolerance in percent; default its own, 0.01), ISPH_SOLVER
# (keys of the scene's [solver] section for isph, e.g. "cfl = 0.4; tolerance = 1e-4", to compare
# at another time step or PPE tolerance; default none: the scene's defaults).
set -euo pipefail
SPACING=${1:-0.02}
UNTIL=${2:-0.3}
THREADS=${3:-2}
SOLVERS=${4:-"DFSPH IISPH"}
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ISPH=${ISPH:-$ROOT/target/release/isph}
WORK=${WORK:-/tmp/isph_peers_dambreak_3d}
VENV=${SPLASH_VENV:-/tmp/peers_splash_venv}
mkdir -p "$WORK"

# SPlisHSPlasH, as ../shared/peers/splishsplash_dambreak.sh installs it: the wheel loads the
# system's libGL/libX11 even headless.
if [ ! -e /usr/lib/x86_64-linux-gnu/libGLdispatch.so.0 ] || [ ! -e /usr/lib/x86_64-linux-gnu/libGL.so.1 ]; then
  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libgl1 libglvnd0 libx11-6 libxext6 >/dev/null
fi
if [ ! -x "$VENV/bin/python" ]; then
  python3 -m venv "$VENV"
  "$VENV/bin/pip" install -q "pysplishsplash==2.19.0"
fi
python3 -c "import h5py, numpy" 2>/dev/null || python3 -m pip install -q h5py numpy
if [ ! -x "$ISPH" ]; then
  (cd "$ROOT" && cargo build --release)
fi

# isph: the shipped scene at this spacing, with no frame between the first and the last.
SCENE="$WORK/dam_break_3d.toml"
sed -e "s/^spacing = [0-9.e-]*/spacing = $SPACING/" \
    -e "s/^end_time = [0-9.e-]*/end_time = $UNTIL/" \
    -e "s/^output_interval = [0-9.e-]*/output_interval = $UNTIL/" \
    "$ROOT/scenes/dam_break_3d.toml" > "$SCENE"
if [ -n "${ISPH_SOLVER:-}" ]; then
  printf '\n[solver]\n%s\n' "$(echo "$ISPH_SOLVER" | tr ';' '\n' | sed 's/^ *//')" >> "$SCENE"
  echo "isph [solver]: $ISPH_SOLVER"
fi
for key in "spacing = $SPACING" "end_time = $UNTIL" "output_interval = $UNTIL"; do
  grep -q "^$key" "$SCENE" || { echo "error: could not set \`$key\` in $SCENE (has scenes/dam_break_3d.toml changed?)" >&2; exit 1; }
done

echo "isph: dx = $SPACING m to t = $UNTIL s on $THREADS threads (log: $WORK/isph.log) ..."
"$ISPH" run "$SCENE" --out "$WORK/isph" --until "$UNTIL" --threads "$THREADS" --overwrite -q > "$WORK/isph.log" 2>&1 \
  || { cat "$WORK/isph.log" >&2; exit 1; }

SPLASH_LINES=()
for SOLVER in $SOLVERS; do
  LOG="$WORK/splash_$SOLVER.log"
  echo "SPlisHSPlasH $SOLVER: radius $(python3 -c "print($SPACING / 2)") m to t = $UNTIL s on $THREADS threads (log: $LOG) ..."
  # Importing the module segfaults in __glDispatchInit unless the system's libGLdispatch is
  # preloaded (the wheel's own clashes with it); see ../shared/peers/splishsplash_dambreak.sh.
  LD_PRELOAD=/usr/lib/x86_64-linux-gnu/libGLdispatch.so.0 OMP_NUM_THREADS=$THREADS \
    "$VENV/bin/python" "$ROOT/tools/splishsplash_dambreak_3d.py" --solver "$SOLVER" \
    --spacing "$SPACING" --stop "$UNTIL" ${MAXERROR:+--maxerror "$MAXERROR"} \
    --workdir "$WORK/splash_$SOLVER" > "$LOG" 2>&1 \
    || { cat "$LOG" >&2; exit 1; }
  LINE=$(grep '^peer=splishsplash ' "$LOG" | tail -1)
  [ -n "$LINE" ] || { echo "error: SPlisHSPlasH $SOLVER printed no result line; see $LOG" >&2; exit 1; }
  SPLASH_LINES+=("$LINE")
done

echo
echo "3D dam break, tank 1.0 x 0.4 x 0.6 m, block 0.3 x 0.4 x 0.5 m, dx = $SPACING m, to t = $UNTIL s, $THREADS threads"
python3 "$ROOT/tools/peers_report.py" "$WORK/isph" "$SCENE" "${SPLASH_LINES[@]}"
