#!/usr/bin/python3
"""Liquid volume inside the bunny, per frame: a leak check for examples/bunny.

Usage (repository root; Debian's python3 with python3-openvdb and python3-numpy):
    /usr/bin/python3 examples/bunny/leak_check.py out/bunny [examples/bunny/bunny.vdb]

For each out/bunny/liquid.NNNN.vdb it counts the voxels inside the liquid surface (phi < 0)
that are also deeper than one particle spacing h = 1 cm inside the bunny (phi_bunny < -h), and
prints that volume beside the liquid's whole volume. The liquid surface is a smoothed particle
surface reaching about h/2 beyond the particles, so liquid on the bunny's skin never counts.
"""
import glob
import sys
import numpy as np
import pyopenvdb as vdb

H = 0.01


def dense(grid, lo, hi):
    shape = tuple(int(h - l + 1) for l, h in zip(lo, hi))
    a = np.empty(shape, dtype=np.float32)
    grid.copyToArray(a, ijk=lo)
    return a


def main(run, solid='examples/bunny/bunny.vdb'):
    bunny = vdb.read(solid, 'surface')
    print(f"{'frame':>5} {'liquid (L)':>10} {'inside bunny deeper than h (L)':>31}")
    worst = 0.0
    for path in sorted(glob.glob(f'{run}/liquid.[0-9]*.vdb')):
        liquid = vdb.read(path, 'surface')
        vs = liquid.transform.voxelSize()[0]
        lo, hi = liquid.evalActiveVoxelBoundingBox()
        phi = dense(liquid, lo, hi)
        phib = dense(bunny, lo, hi)   # same 5 mm voxels, same origin
        inside = phi < 0
        leak = inside & (phib < -H)
        frame = int(path[-8:-4])
        v, l = inside.sum() * vs ** 3 * 1000, leak.sum() * vs ** 3 * 1000
        worst = max(worst, l / max(v, 1e-12))
        print(f'{frame:5d} {v:10.3f} {l:31.4f}')
    print(f'largest share of the liquid volume deeper than h inside the bunny: {100 * worst:.2f} %')


if __name__ == '__main__':
    main(*sys.argv[1:])
