#!/usr/bin/env bash
# Runs every benchmark in bench/ and prints the results. Record numbers worth keeping in
# bench/RESULTS.md together with the machine (lscpu) and this command.
set -euo pipefail
build=${1:-build}
echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; load: $(cut -d' ' -f1-3 /proc/loadavg)"
"$build/bench/bench_neighbors" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
"$build/bench/bench_sampler" --benchmark_counters_tabular=true
# Liquid scene benchmark ([SB12] Sec. 5): dam break of ~100k liquid particles and a sphere drop,
# Ghost and Basic SPH (a few minutes, mostly sampling the solids).
"$build/bench/bench_liquid"
# Frame output cost (points, surface, density, velocity) for 1e5 and 1e6 particles (about 2 min).
"$build/bench/bench_frame_write"
# [RYY15] boiling scene: fast gas vs the ambient-air baseline (a few minutes).
"$build/bench/bench_gas" --steps 20 --baseline-steps 3
