#!/bin/sh
# What whitewater costs: each example run with and without outputs.whitewater, interleaved
# (this VM drifts 15-20 % within minutes), then `ghostfx whitewater` over the run's points files.
#
#   bench/whitewater.sh [BUILD_DIR] [ROUNDS]
#
# Prints one line per run: the example, whitewater on or off, and the wall time (s) of the run
# with its points files only (no volumes, meshes or previews, so the difference is the
# whitewater step and its file); then the post-process's frames per second.
set -eu
BUILD=${1:-build}
ROUNDS=${2:-2}
GHOSTFX=$BUILD/cmd/ghostfx
OUT=${TMPDIR:-/tmp}/ghostfx_bench_whitewater
rm -rf "$OUT"

run() { # example frames whitewater(true|false)
    start=$(date +%s.%N)
    "$GHOSTFX" run "examples/$1/scene.json" --frames "$2" --out "$OUT/$1_$3" --progress none \
        -D outputs.whitewater="$3" -D outputs.volume=false -D outputs.preview=false \
        -D outputs.mesh=false -D outputs.checkpoint=false \
        -D 'outputs.points={"channels":["v","id"]}' >/dev/null
    end=$(date +%s.%N)
    echo "$1 frames $2 whitewater=$3: $(echo "$end - $start" | bc) s"
}

for round in $(seq "$ROUNDS"); do
    for example in "dam_break 1-36" "double_dam_break 1-24"; do
        set -- $example
        run "$1" "$2" false
        run "$1" "$2" true
    done
done
for example in dam_break double_dam_break; do
    echo "post-process $example: $("$GHOSTFX" whitewater "$OUT/${example}_false" -q | tail -1)"
done
