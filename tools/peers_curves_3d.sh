#!/usr/bin/env bash
# Wall time per simulated second against compression, as curves: isph over a list of [solver]
# settings (CFL number × PPE tolerance) and SPlisHSPlasH's DFSPH and IISPH over a list of their
# density tolerances, on the 3D dam break of tools/peers_dambreak_3d.sh (same tank, block,
# spacing and CFL-type time-step rule), through the impact on the far wall. The runs alternate
# between the codes, ROUNDS times; every run is one row of $WORK/curves.csv, and
# tools/peers_curves.py prints the medians and draws $WORK/curves.png.
#
# Usage: tools/peers_curves_3d.sh [SPACING=0.02] [UNTIL=0.6] [THREADS=2] [ROUNDS=3]
# Environment: ISPH_SETTINGS (isph's [solver] settings, '|' between settings, ';' between the
# keys of one, e.g. 'kernel = "wendland_c2"; h_over_dx = 1.8'; default "cfl = 0.24|cfl = 0.4|cfl = 0.6|cfl = 0.4; tolerance = 1e-6|cfl = 0.4; tolerance = 1e-3|cfl = 0.6; tolerance = 1e-3"),
# MAXERRORS (SPlisHSPlasH's density tolerances in percent; default "0.01 0.1 1"), SOLVERS
# (default "DFSPH IISPH"), ISPH, WORK (default /tmp/isph_peers_curves_3d), SPLASH_VENV.
set -euo pipefail
SPACING=${1:-0.02}
UNTIL=${2:-0.6}
THREADS=${3:-2}
ROUNDS=${4:-3}
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ISPH=${ISPH:-$ROOT/target/release/isph}
WORK=${WORK:-/tmp/isph_peers_curves_3d}
VENV=${SPLASH_VENV:-/tmp/peers_splash_venv}
ISPH_SETTINGS=${ISPH_SETTINGS:-"cfl = 0.24|cfl = 0.4|cfl = 0.6|cfl = 0.4; tolerance = 1e-6|cfl = 0.4; tolerance = 1e-3|cfl = 0.6; tolerance = 1e-3"}
MAXERRORS=${MAXERRORS:-"0.01 0.1 1"}
SOLVERS=${SOLVERS:-"DFSPH IISPH"}
mkdir -p "$WORK"

. "$ROOT/tools/peers_common.sh"
python3 -c "import matplotlib" 2>/dev/null || python3 -m pip install -q matplotlib

CSV="$WORK/curves.csv"
echo "round,code,setting,steps,iterations_mean,wall_per_sim_second,compression_mean" > "$CSV"
IFS='|' read -r -a SETTINGS <<< "$ISPH_SETTINGS"
read -r -a ERRORS <<< "$MAXERRORS"
if [ "${#ERRORS[@]}" -gt "${#SETTINGS[@]}" ]; then
  echo "error: MAXERRORS has more tolerances (${#ERRORS[@]}) than ISPH_SETTINGS has settings (${#SETTINGS[@]}): each SPlisHSPlasH tolerance runs after the isph setting in its place" >&2
  exit 2
fi
for round in $(seq 1 "$ROUNDS"); do
  for k in "${!SETTINGS[@]}"; do
    setting=${SETTINGS[$k]}
    echo "round $round: isph [$setting] to t = $UNTIL s ..."
    isph_scene "$setting" "$WORK/isph_$k.toml"
    run_isph "$WORK/isph_$k.toml" "$WORK/isph_$k" "$WORK/isph_$k.log"
    python3 "$ROOT/tools/peers_curves.py" isph "$round" "$setting" "$WORK/isph_$k" "$WORK/isph_$k.toml" >> "$CSV"
    # SPlisHSPlasH's k-th tolerance after isph's k-th setting, so the codes alternate.
    [ "$k" -lt "${#ERRORS[@]}" ] || continue
    maxerror=${ERRORS[$k]}
    for SOLVER in $SOLVERS; do
      echo "round $round: SPlisHSPlasH $SOLVER at $maxerror% ..."
      line=$(run_splash "$SOLVER" "$maxerror" "$WORK/splash_$SOLVER" "$WORK/splash_$SOLVER.log")
      python3 "$ROOT/tools/peers_curves.py" splash "$round" "$maxerror%" "$line" >> "$CSV"
    done
  done
done
echo
echo "3D dam break, dx = $SPACING m, to t = $UNTIL s, $THREADS threads, $ROUNDS rounds: $CSV"
python3 "$ROOT/tools/peers_curves.py" summary "$CSV" -o "$WORK/curves.png"
