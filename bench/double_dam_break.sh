#!/usr/bin/env bash
# Cost per step of the [SB12] Sec. 5 double dam break ("750k particles ... averaged 21.4 s per
# step" on a quad-core i7-2600) at full size: examples/double_dam_break/scene.json with a finer
# spacing, walls kept 3 h thick, a fixed step and only the statistics written.
#
#   bench/double_dam_break.sh [ghostfx] [spacing] [threads] [frames]
#   defaults:  build/cmd/ghostfx  0.0032  1  1-2
#   GHOSTFX_BENCH_ARGS: more -D settings, e.g. "-D settings.sampling_relaxation=sb12"
#   GHOSTFX_BENCH_OUT: the output directory (default out/double_dam_break_bench)
#
# h = 3.2 mm gives 750k liquid particles, the paper's count. The step is fixed at 20 substeps per
# frame as in the paper, with frame_rate 150 so that dt = 1/3000 s (c dt / h = 0.39 at
# k = 2000 Pa; the paper's dt = 1/600 s is beyond the acoustic limit at this spacing). Results
# are recorded in bench/RESULTS.md ("Double dam break at the paper's size").
set -euo pipefail
ghostfx=${1:-build/cmd/ghostfx}
h=${2:-0.0032}
threads=${3:-1}
frames=${4:-1-2}
out=${GHOSTFX_BENCH_OUT:-out/double_dam_break_bench}
wall=$(python3 -c "print(round(3 * $h, 6))")
mkdir -p "$out"
echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; load: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "h = $h m, walls $wall m, $threads thread(s), frames $frames"
/usr/bin/time -v -o "$out/time.txt" "$ghostfx" run examples/double_dam_break/scene.json --threads "$threads" \
    --frames "$frames" --out "$out" --progress log \
    -D settings.spacing="$h" -D settings.substeps=20 -D settings.frame_rate=150 \
    -D "solids[0].geometry.container.wall=$wall" \
    -D outputs.points=false -D outputs.volume=false -D outputs.preview=false \
    -D outputs.checkpoint=false -D outputs.stats.file=stats.h5 ${GHOSTFX_BENCH_ARGS:-}
grep -E 'Elapsed|Maximum resident|User time|System time' "$out/time.txt"
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$out/stats.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
f = lambda r, k: float(r[k])
t = [f(r, 't_step') for r in rows]
later = t[1:] or t
r = rows[-1]
liquid, air, solid = (int(f(r, k)) for k in ('count_liquid', 'count_ghost_air', 'count_ghost_solid'))
print(f"steps {len(rows)}; liquid {liquid:,}, ghost air {air:,} ({100*air/liquid:.0f} %), "
      f"ghost solid {solid:,} ({100*solid/liquid:.0f} %), all {liquid+air+solid:,}")
print(f"first step (air layer + mass scaling) {t[0]:.2f} s; steps 2-{len(rows)}: mean {sum(later)/len(later):.2f} s, "
      f"min {min(later):.2f} s, max {max(later):.2f} s")
phases = ['t_neighbors_density', 't_pressure_force', 't_xsph_boundary', 't_air_resampling']
tot = sum(later)
print('share of steps 2-: ' + ', '.join(f"{p[2:]} {100*sum(f(x, p) for x in rows[1:])/tot:.0f} %" for p in phases))
print(f"max speed at the end {f(r, 'max_speed'):.3f} m/s, density error mean {f(r, 'density_error_mean'):.4f}")
PY
