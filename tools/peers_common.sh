# Shared by tools/peers_dambreak_3d.sh and tools/peers_curves_3d.sh (sourced): installs
# SPlisHSPlasH and the Python packages if missing, builds isph if missing, and writes isph's
# scene; `run_isph` and `run_splash` run one point each.
# Expects ROOT, ISPH, WORK, VENV, SPACING, UNTIL and THREADS to be set.

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

# isph_scene SETTINGS FILE: the shipped scene at this spacing, with no frame between the first
# and the last, and SETTINGS (keys of [solver] separated by ';', may be empty) appended.
isph_scene() {
  sed -e "s/^spacing = [0-9.e-]*/spacing = $SPACING/" \
      -e "s/^end_time = [0-9.e-]*/end_time = $UNTIL/" \
      -e "s/^output_interval = [0-9.e-]*/output_interval = $UNTIL/" \
      "$ROOT/scenes/dam_break_3d.toml" > "$2"
  if [ -n "$1" ]; then
    printf '\n[solver]\n%s\n' "$(echo "$1" | tr ';' '\n' | sed 's/^ *//')" >> "$2"
  fi
  for key in "spacing = $SPACING" "end_time = $UNTIL" "output_interval = $UNTIL"; do
    grep -q "^$key" "$2" || { echo "error: could not set \`$key\` in $2 (has scenes/dam_break_3d.toml changed?)" >&2; exit 1; }
  done
}

# run_isph SCENE OUT LOG: isph on THREADS threads to UNTIL.
run_isph() {
  "$ISPH" run "$1" --out "$2" --until "$UNTIL" --threads "$THREADS" --overwrite -q > "$3" 2>&1 \
    || { cat "$3" >&2; exit 1; }
}

# run_splash SOLVER MAXERROR DIR LOG: SPlisHSPlasH's SOLVER (DFSPH, IISPH) at the density
# tolerance MAXERROR in percent (empty: its own default); prints its `peer=splishsplash` line.
run_splash() {
  # Importing the module segfaults in __glDispatchInit unless the system's libGLdispatch is
  # preloaded (the wheel's own clashes with it); see ../shared/peers/splishsplash_dambreak.sh.
  LD_PRELOAD=/usr/lib/x86_64-linux-gnu/libGLdispatch.so.0 OMP_NUM_THREADS=$THREADS \
    "$VENV/bin/python" "$ROOT/tools/splishsplash_dambreak_3d.py" --solver "$1" \
    --spacing "$SPACING" --stop "$UNTIL" ${2:+--maxerror "$2"} \
    --workdir "$3" > "$4" 2>&1 \
    || { cat "$4" >&2; exit 1; }
  local line
  line=$(grep '^peer=splishsplash ' "$4" | tail -1)
  [ -n "$line" ] || { echo "error: SPlisHSPlasH $1 printed no result line; see $4" >&2; exit 1; }
  echo "$line"
}
