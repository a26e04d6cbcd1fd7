#!/usr/bin/env bash
# The speed check of a refactoring (issue 55's "no slower"): the liquid, gas and boiling
# benchmarks and the column tank run with build A and build B in turn, ROUNDS times, so the
# VM's drift (15-20 % within minutes) falls on both alike. Prints each run's figure as it
# comes and, at the end, the median of each build and B / A.
#
#   scripts/speed-compare.sh BUILD_A BUILD_B [ROUNDS]     (ROUNDS: default 3)
#   ONLY=dfsph_ms scripts/speed-compare.sh ...              (the cases whose names match)
#
# Figures: ms per measured step (bench_liquid's dam break, Tait and DFSPH; bench_plume's fast
# gas; bench_gas's coupled boiling step) and wall seconds of the column tank's 0.25 s (DFSPH).
set -euo pipefail
cd "$(dirname "$0")/.."
a=$1 b=$2 rounds=${3:-3}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# name | how to run it with build $1 | how to read its figure from stdout
CASES=(
  "tait_ms|\$1/bench/bench_liquid --scene dam --method ghost --threads 2 --warmup 20 --steps 30|sed -n 's/.*step: mean \([0-9.]*\) ms.*/\1/p' | head -1"
  "dfsph_ms|\$1/bench/bench_liquid --scene dam --method ghost --pressure dfsph --threads 2 --warmup 20 --steps 30|sed -n 's/.*step: mean \([0-9.]*\) ms.*/\1/p' | head -1"
  "plume_ms|\$1/bench/bench_plume --steps 300 --ambient-steps 0|sed -n 's/^fast: .*(\([0-9.]*\) ms\/step.*/\1/p' | head -1"
  "boiling_ms|\$1/bench/bench_gas --steps 20 --baseline-steps 0|sed -n 's/^fast: .*(\([0-9.]*\) ms\/step.*/\1/p' | head -1"
  "column_s|/usr/bin/time -f 'wall %e' \$1/cmd/ghostfx run bench/scenes/column_tank.json -q --out $out/col -D settings.pressure=dfsph --sample-cache off 2>&1|sed -n 's/^wall \([0-9.]*\)/\1/p'"
)

for entry in "${CASES[@]}"; do
    IFS='|' read -r name command reader <<< "$entry"
    [[ -n "${ONLY:-}" && ! "$name" =~ ${ONLY} ]] && continue
    for round in $(seq "$rounds"); do
        for build in "$a" "$b"; do
            rm -rf "$out/col"
            value=$(bash -c "$command" _ "$build" | bash -c "$reader")
            echo "$name $build $value" | tee -a "$out/figures"
        done
    done
done

echo
python3 - "$out/figures" "$a" "$b" <<'PY'
import statistics, sys
rows = [line.split() for line in open(sys.argv[1]) if len(line.split()) == 3]
a, b = sys.argv[2], sys.argv[3]
print(f"{'case':12} {'median A':>10} {'median B':>10} {'B / A':>7}")
for name in dict.fromkeys(r[0] for r in rows):
    ma = statistics.median(float(r[2]) for r in rows if r[0] == name and r[1] == a)
    mb = statistics.median(float(r[2]) for r in rows if r[0] == name and r[1] == b)
    print(f"{name:12} {ma:10.2f} {mb:10.2f} {mb / ma:7.3f}")
PY
