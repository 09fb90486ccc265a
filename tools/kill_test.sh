#!/usr/bin/env bash
# Kill test of checkpoint and restart (issue 5). A 2D dam break that checkpoints every few steps
# is killed with SIGKILL at a random moment, KILLS times in a row: first during `isph run`, then
# each time during the `isph resume` of the run's output directory. Every resume must load the
# newest checkpoint on disk (none skipped as damaged) and be running when it is killed. A last
# resume runs on to a little after the newest checkpoint, and the run is compared with one never
# interrupted, bit for bit: every frame of particles.h5, every row of stats.csv (but
# wall_seconds) and the arrays of the final checkpoint.
#
#   tools/kill_test.sh [KILLS]      # default 20; about a minute on 2 cores
set -euo pipefail
kills=${1:-20}
cd "$(dirname "$0")/.."
cargo build --release -q
isph=$PWD/target/release/isph
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

scene=$work/kill_test.toml
sed -e 's/^spacing = 0.001905 .*/spacing = 0.00381/' \
    -e 's/^end_time = 1.0 .*/end_time = 5.0/' \
    -e 's/^output_interval = 0.01 .*/output_interval = 0.005/' \
    scenes/dam_break_2d.toml > "$scene"
printf '\n[checkpoint]\ninterval = 0.002\nwall_interval = 0.25\nkeep = 2\n' >> "$scene"

out=$work/killed
resumed=0
for k in $(seq 1 "$kills"); do
    if [ "$k" -eq 1 ]; then
        "$isph" run "$scene" --out "$out" -q --threads 1 > /dev/null 2> "$work/stderr" &
    else
        "$isph" resume "$out" -q --threads 1 > /dev/null 2> "$work/stderr" &
    fi
    pid=$!
    # A run is worth killing once it has a checkpoint to resume from.
    until compgen -G "$out/checkpoints/step_*.ckpt" > /dev/null; do sleep 0.01; done
    # 0.2 to 1.2 s: long after a resume has loaded its checkpoint (milliseconds), so a process
    # still running then has resumed.
    sleep "$(printf '%d.%03d' $((RANDOM % 2)) $((RANDOM % 1000)))"
    sleep 0.2
    kill -9 "$pid" 2> /dev/null || true
    status=0
    wait "$pid" 2> /dev/null || status=$?
    if [ "$status" -ne 137 ]; then
        echo "kill $k: the process had already ended with status $status:" >&2
        cat "$work/stderr" >&2
        exit 1
    fi
    if grep -q skipped "$work/stderr"; then
        echo "kill $k: a resume skipped a damaged checkpoint:" >&2
        cat "$work/stderr" >&2
        exit 1
    fi
    [ "$k" -gt 1 ] && resumed=$((resumed + 1))
    newest=$(compgen -G "$out/checkpoints/step_*.ckpt" | sort | tail -1)
    echo "kill $k: killed at step $(tail -1 "$out/stats.csv" | cut -d, -f1), newest checkpoint $(basename "$newest")"
done

# The simulated time of the newest checkpoint: the f64 at byte 56 (docs/checkpoint-format.md).
newest=$(compgen -G "$out/checkpoints/step_*.ckpt" | sort | tail -1)
until=$(python3 -c 'import struct, sys; print(struct.unpack_from("=d", open(sys.argv[1], "rb").read(64), 56)[0] + 0.02)' "$newest")
echo "final resume to t = $until s, and a reference run never interrupted"
"$isph" resume "$out" --until "$until" -q > /dev/null 2> "$work/stderr" || { cat "$work/stderr" >&2; exit 1; }
if grep -q skipped "$work/stderr"; then cat "$work/stderr" >&2; exit 1; fi
resumed=$((resumed + 1))
"$isph" run "$scene" --out "$work/reference" --until "$until" -q > /dev/null

# stats.csv without wall_seconds, the final checkpoints after their fixed 112-byte header
# (which holds the wall time and the checksum over it), and every frame.
diff <(cut -d, -f1-9,11- "$work/reference/stats.csv") <(cut -d, -f1-9,11- "$out/stats.csv") > /dev/null ||
    { echo "stats.csv differs from the reference" >&2; exit 1; }
last() { compgen -G "$1/checkpoints/step_*.ckpt" | sort | tail -1; }
cmp <(tail -c +113 "$(last "$work/reference")") <(tail -c +113 "$(last "$out")") ||
    { echo "the final checkpoint differs from the reference" >&2; exit 1; }
python3 - "$work/reference/particles.h5" "$out/particles.h5" <<'EOF'
import sys
import h5py

a, b = (h5py.File(p, "r") for p in sys.argv[1:3])
assert sorted(a) == sorted(b), f"frames differ: {sorted(a)} vs {sorted(b)}"
for frame in a:
    for key in ("time", "step"):
        assert a[frame].attrs[key] == b[frame].attrs[key], f"{frame} {key} differs"
    for name in a[frame]:
        assert a[frame][name][()].tobytes() == b[frame][name][()].tobytes(), f"{frame}/{name} differs"
print(f"{len(a)} frames bit-identical to the reference")
EOF
echo "kill test passed: $kills kills with SIGKILL, $resumed resumes from the newest checkpoint, stats.csv, frames and final state identical to the uninterrupted run"
