#!/usr/bin/python3
"""How far the liquid wraps around the tomato, from the surface level sets of a run.

Usage (repository root, Debian's python3 with python3-openvdb and python3-numpy):
    /usr/bin/python3 examples/tomato/wrap_stats.py out/tomato out/tomato_basic [--frames 15-45]

For each run folder it reads liquid.NNNN.vdb (grid 'surface'), and for every voxel centre in a
shell R < r < R + 1.5 h around the sphere (the tomato: centre (0, 0.35, 0), R = 0.06 m,
h = 0.01 m, or TOMATO_H) it records whether it is inside the liquid (phi < 0). It prints, averaged over the
frames, the fraction of the shell covered by liquid in 30-degree latitude bands measured from the
top of the sphere (0-30 = the cap under the tap, 150-180 = the underside), and the share of the
liquid volume below the sphere (y < cy - R) that lies within the sphere's shadow (x^2 + z^2 < R^2):
near 1 when the liquid leaves in a stream from the bottom, small when it falls off the sides.
"""
import os
import sys
import numpy as np
import pyopenvdb as vdb

CENTER = np.array([0.0, 0.35, 0.0])
R = float(os.environ.get("TOMATO_R", "0.06"))   # sphere radius (m); TOMATO_R for variants
H = float(os.environ.get("TOMATO_H", "0.01"))   # spacing h (m) that sets the shell; TOMATO_H for the paper size
BANDS = [(0, 30), (30, 60), (60, 90), (90, 120), (120, 150), (150, 180)]


def frame_stats(path):
    grid = vdb.read(path, 'surface')
    (lo, hi) = grid.evalActiveVoxelBoundingBox()
    shape = tuple(int(h - l + 1) for l, h in zip(lo, hi))
    phi = np.empty(shape, dtype=np.float32)
    grid.copyToArray(phi, ijk=lo)
    vs = grid.transform.voxelSize()[0]
    axes = [(np.arange(n) + l) * vs for n, l in zip(shape, lo)]
    x, y, z = np.meshgrid(*axes, indexing='ij')
    inside = phi < 0
    d = np.stack([x - CENTER[0], y - CENTER[1], z - CENTER[2]])
    r = np.sqrt((d ** 2).sum(axis=0))
    polar = np.degrees(np.arccos(np.clip(d[1] / np.maximum(r, 1e-9), -1, 1)))  # 0 = top
    shell = (r > R) & (r < R + 1.5 * H)
    # liquid volume in each band over the band's exact volume: shell voxels outside the
    # liquid's bounding box are dry (so coverage can exceed 1 by the voxelisation, a few %)
    full = []
    for a, b in BANDS:
        vol = 2 * np.pi / 3 * ((R + 1.5 * H) ** 3 - R ** 3) * (np.cos(np.radians(a)) - np.cos(np.radians(b)))
        band = shell & (polar >= a) & (polar < b)
        full.append(inside[band].sum() * vs ** 3 / vol)
    below = inside & (y < CENTER[1] - R)
    shadow = below & (d[0] ** 2 + d[2] ** 2 < R ** 2)
    stream = shadow.sum() / max(below.sum(), 1)
    return np.array(full), stream, inside.sum() * vs ** 3


def main(argv):
    frames = (15, 45)
    dirs = []
    it = iter(argv)
    for a in it:
        if a == '--frames':
            f = next(it).split('-')
            frames = (int(f[0]), int(f[1]))
        else:
            dirs.append(a)
    print('coverage of the shell R < r < R + 1.5 h by 30-degree band from the top, '
          f'mean over frames {frames[0]}-{frames[1]}')
    print(f"{'run':24s} " + ' '.join(f'{a:>3d}-{b:<3d}' for a, b in BANDS) + '  stream  volume (L)')
    for d in dirs:
        cov, streams, vols = [], [], []
        for f in range(frames[0], frames[1] + 1):
            c, s, v = frame_stats(f'{d}/liquid.{f:04d}.vdb')
            cov.append(c); streams.append(s); vols.append(v)
        cov = np.mean(cov, axis=0)
        print(f'{d:24s} ' + ' '.join(f'{c:7.2f}' for c in cov)
              + f'  {np.mean(streams):6.2f}  {1000 * np.mean(vols):6.2f}')


if __name__ == '__main__':
    main(sys.argv[1:])
