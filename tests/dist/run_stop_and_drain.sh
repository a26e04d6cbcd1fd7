#!/usr/bin/env bash
# `mpirun -np 2 ghostfx run` against what a farm throws at it (tests/CMakeLists.txt runs it):
#  1. one process's slab drains out of the kill box while the other's liquid stays: the run
#     goes on to its last frame;
#  2. all the liquid drains: the run ends with exit 0 and one warning line;
#  3. SIGUSR1 to mpirun (which forwards it to every process; Slurm's --signal=USR1@60): both
#     processes stop after the same frame, write one checkpoint (a manifest and a file each),
#     exit with 138, and the printed resume command, pasted as it is, continues the run.
# usage: run_stop_and_drain.sh GHOSTFX MPIEXEC OUT
set -euo pipefail
ghostfx=$1 mpiexec=$2 out=$3
rm -rf "$out" && mkdir -p "$out" && cd "$out"
two=("$mpiexec" -np 2 --oversubscribe)
fail() { echo "FAIL: $*" >&2; exit 1; }

# 1. Two blocks of water, one over the kill box's floor, one on a ledge: the domain is cut
# between them, and the first process's block falls out within five frames.
cat > slab.json <<'JSON'
{ "ghostfx_scene": 1,
  "settings": { "method": "ghost", "spacing": 0.02, "substeps": 0, "frame_range": [1, 8], "seed": 2 },
  "solids": [ { "name": "ledge", "geometry": { "box": { "min": [0.4, 0.24, -0.1], "max": [0.8, 0.35, 0.2] } } } ],
  "liquids": [ { "name": "falling", "geometry": { "box": { "min": [0, 0.35, 0], "max": [0.1, 0.42, 0.1] } } },
               { "name": "resting", "geometry": { "box": { "min": [0.5, 0.35, 0], "max": [0.7, 0.42, 0.1] } } } ],
  "domain": { "kill_box": { "min": [-0.3, 0.3, -0.3], "max": [1.0, 1.0, 0.4] } } }
JSON
"${two[@]}" "$ghostfx" run slab.json --out slab --threads 1 -q || fail "a drained slab: exit $?"
[ -s slab/liquid_points.0008.vdb ] || fail "a drained slab: no frame 8"

# 2. The falling block alone: every particle leaves.
cat > all.json <<'JSON'
{ "ghostfx_scene": 1,
  "settings": { "method": "ghost", "spacing": 0.02, "substeps": 0, "frame_range": [1, 8], "seed": 2 },
  "liquids": [ { "name": "falling", "geometry": { "box": { "min": [0, 0.35, 0], "max": [0.1, 0.42, 0.1] } } } ],
  "domain": { "kill_box": { "min": [-0.3, 0.3, -0.3], "max": [1.0, 1.0, 0.4] } } }
JSON
"${two[@]}" "$ghostfx" run all.json --out all --threads 1 -q 2> all.err || fail "all drained: exit $?"
warnings=$(grep -c "no liquid particles are left" all.err || true)
[ "$warnings" = 1 ] || fail "all drained: $warnings warning lines, expected 1: $(cat all.err)"

# 3. A long run with fixed substeps, stopped by SIGUSR1 after its second frame.
cat > long.json <<'JSON'
{ "ghostfx_scene": 1,
  "settings": { "method": "ghost", "spacing": 0.012, "substeps": 15, "frame_range": [1, 4000], "seed": 7 },
  "solids": [ { "name": "tank", "geometry": { "container": { "min": [0, 0, 0], "max": [0.3, 0.3, 0.3] } } } ],
  "liquids": [ { "name": "water", "geometry": { "box": { "min": [0, 0, 0], "max": [0.12, 0.12, 0.3] } } } ],
  "outputs": { "checkpoint": { "every": 1000 } } }
JSON
"${two[@]}" "$ghostfx" run long.json --out stop --threads 1 --progress none \
    -D 'outputs.checkpoint.file=state.$F4.h5' 2> stop.err &
pid=$!
for _ in $(seq 600); do [ -e stop/liquid.0002.vdb ] && break; sleep 0.1; done
kill -USR1 $pid
code=0
wait $pid || code=$?
[ "$code" = 138 ] || fail "SIGUSR1: exit $code, expected 138: $(cat stop.err)"
line=$(grep "ghostfx: stopped by SIGUSR1 after frame" stop.err) || fail "no stop line: $(cat stop.err)"
[ "$(grep -c "stopped by" stop.err)" = 1 ] || fail "the stop line is printed by one process only"
frame=$(echo "$line" | sed 's/.*after frame \([0-9]*\);.*/\1/')
manifest=$(printf 'stop/state.%04d.ranks.json' "$frame")
for f in "$manifest" "$(printf 'stop/state.%04d.rank0.h5' "$frame")" \
         "$(printf 'stop/state.%04d.rank1.h5' "$frame")"; do
    [ -s "$f" ] || fail "SIGUSR1 after frame $frame: no $f"
done
command=$(echo "$line" | sed 's/.*resume with: //')
case "$command" in "mpirun -np 2 ghostfx run long.json --out stop -D "*"--resume $manifest") ;;
    *) fail "the resume command is not the run's own: $command" ;; esac
# Pasted as it is (with this build's programs), two frames on.
sed -i "s/\"frame_range\": \[1, 4000\]/\"frame_range\": [1, $((frame + 2))]/" long.json
pasted=${command/mpirun -np 2 ghostfx/${two[*]} $ghostfx}
eval "$pasted -q" || fail "the pasted resume command failed: $pasted"
[ -s "$(printf 'stop/liquid.%04d.vdb' $((frame + 2)))" ] || fail "the resumed run wrote no frame $((frame + 2))"
echo "stopped after frame $frame with exit 138; resumed to frame $((frame + 2))"
