#!/usr/bin/env python3
"""[SB12] Table 1 statistics of a ghostfx run, from its stats.csv.

    python3 examples/table1.py out/tomato/stats.csv [out/tomato_basic/stats.csv ...] [--from-frame F] [--to-frame T]

Per run: the mean liquid particle count over the steps, the ghost-solid and ghost-air overheads
(mean ghost count / mean liquid count, [SB12]'s "ratio of ghost particles to real liquid
particles"), the mean steps per frame, and the mean wall time per step and per frame from the
solver's own t_step (the solver step; frame output such as previews and VDB files is not in it).
The first step (it also grows the first air layer and scales the particle mass) is left out of
the per-step mean and counted in the per-frame time.
"""
import csv
import sys


def main(argv):
    lo, hi, paths = 1, 10 ** 9, []
    it = iter(argv)
    for a in it:
        if a == '--from-frame':
            lo = int(next(it))
        elif a == '--to-frame':
            hi = int(next(it))
        else:
            paths.append(a)
    print(f"{'run':34s} {'frames':>7s} {'steps':>6s} {'liquid':>7s} {'solid %':>8s} {'air %':>6s} "
          f"{'steps/frame':>11s} {'ms/step':>8s} {'s/frame':>8s}")
    for p in paths:
        rows = [r for r in csv.DictReader(open(p)) if lo <= int(float(r['frame'])) <= hi]
        g = lambda k: [float(r[k]) for r in rows]
        n = len(rows)
        liquid = sum(g('count_liquid')) / n
        air = sum(g('count_ghost_air')) / n
        solid = sum(g('count_ghost_solid')) / n + sum(g('count_boundary')) / n
        t = g('t_step')
        first = 1 if int(float(rows[0]['step'])) == 1 else 0
        per_step = sum(t[first:]) / max(1, n - first)
        frames = sorted({int(float(r['frame'])) for r in rows})
        per_frame = sum(t) / len(frames)
        print(f"{p:34s} {frames[0]:>3d}-{frames[-1]:<3d} {n:6d} {liquid:7.0f} {100 * solid / liquid:7.0f}% "
              f"{100 * air / liquid:5.0f}% {n / len(frames):11.1f} {1000 * per_step:8.1f} {per_frame:8.2f}")


if __name__ == '__main__':
    main(sys.argv[1:])
