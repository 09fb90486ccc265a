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

. "$ROOT/tools/peers_common.sh"

SCENE="$WORK/dam_break_3d.toml"
isph_scene "${ISPH_SOLVER:-}" "$SCENE"
[ -z "${ISPH_SOLVER:-}" ] || echo "isph [solver]: $ISPH_SOLVER"
echo "isph: dx = $SPACING m to t = $UNTIL s on $THREADS threads (log: $WORK/isph.log) ..."
run_isph "$SCENE" "$WORK/isph" "$WORK/isph.log"

SPLASH_LINES=()
for SOLVER in $SOLVERS; do
  LOG="$WORK/splash_$SOLVER.log"
  echo "SPlisHSPlasH $SOLVER: radius $(python3 -c "print($SPACING / 2)") m to t = $UNTIL s on $THREADS threads (log: $LOG) ..."
  SPLASH_LINES+=("$(run_splash "$SOLVER" "${MAXERROR:-}" "$WORK/splash_$SOLVER" "$LOG")")
done

echo
echo "3D dam break, tank 1.0 x 0.4 x 0.6 m, block 0.3 x 0.4 x 0.5 m, dx = $SPACING m, to t = $UNTIL s, $THREADS threads"
python3 "$ROOT/tools/peers_report.py" "$WORK/isph" "$SCENE" "${SPLASH_LINES[@]}"
