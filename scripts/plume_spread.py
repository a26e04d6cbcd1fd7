#!/usr/bin/env python3
"""The spread of a gas plume from its points files: per height bin, the top-hat radius
b = sqrt(2) r_rms of the gas about the bin's own axis (r_rms the mass-weighted RMS distance from
the bin's centre of mass in the horizontal plane; a uniform disc of radius b has r_rms = b / sqrt(2)),
averaged over the frames given, and the slope db/dz of a least-squares line over [z0, z1].

    PYTHONPATH=build/python python3 scripts/plume_spread.py out/gas_plume --frames 30-48 \
        --z0 0.3 --z1 1.2 [--source-height 0.12] [--bin 0.05]

Morton, Taylor and Turner (1956): b = (6/5) alpha z above a point source, alpha about 0.1, so
db/dz is about 0.12. Prints one line per bin (z, b, particles) and the slope."""
import argparse
import glob
import os

import numpy as np

import ghostfx


def frame_files(folder, first, last):
    files = []
    for f in range(first, last + 1):
        path = os.path.join(folder, "gas_points.%04d.vdb" % f)
        if os.path.exists(path):
            files.append(path)
    return files


def bin_radii(points, edges, mass_key="mass"):
    """Per bin of heights `edges`: (sum of b^2 m, sum of m, count) of one frame."""
    p = points["P"]
    m = points[mass_key].astype(float) if mass_key in points else np.ones(len(p))
    out = []
    for lo, hi in zip(edges[:-1], edges[1:]):
        sel = (p[:, 1] >= lo) & (p[:, 1] < hi)
        if sel.sum() < 8:
            out.append(None)
            continue
        q, w = p[sel], m[sel]
        centre = (q[:, [0, 2]] * w[:, None]).sum(axis=0) / w.sum()
        r2 = ((q[:, [0, 2]] - centre) ** 2).sum(axis=1)
        out.append((2.0 * (r2 * w).sum() / w.sum(), int(sel.sum())))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folder")
    ap.add_argument("--frames", default="1-100000")
    ap.add_argument("--z0", type=float, required=True)
    ap.add_argument("--z1", type=float, required=True)
    ap.add_argument("--bin", type=float, default=0.05)
    args = ap.parse_args()
    first, last = (int(v) for v in args.frames.split("-"))
    files = frame_files(args.folder, first, last)
    if not files:
        raise SystemExit("plume_spread: no gas_points.*.vdb in %s for frames %s" % (args.folder, args.frames))
    edges = np.arange(args.z0, args.z1 + 0.5 * args.bin, args.bin)
    b2 = np.zeros(len(edges) - 1)
    counts = np.zeros(len(edges) - 1)
    frames = np.zeros(len(edges) - 1)
    for path in files:
        for k, r in enumerate(bin_radii(ghostfx.read_points(path), edges)):
            if r is None:
                continue
            b2[k] += r[0]
            counts[k] += r[1]
            frames[k] += 1
    z = 0.5 * (edges[:-1] + edges[1:])
    ok = frames > 0
    b = np.sqrt(b2[ok] / frames[ok])
    for zk, bk, nk in zip(z[ok], b, counts[ok] / frames[ok]):
        print("z %.3f m: b %.4f m (%.0f particles)" % (zk, bk, nk))
    if ok.sum() >= 2:
        slope, intercept = np.polyfit(z[ok], b, 1)
        print("db/dz = %.4f over z %.2f-%.2f m (b = %.4f + %.4f z), %d frames" %
              (slope, args.z0, args.z1, intercept, slope, len(files)))


if __name__ == "__main__":
    main()
