#!/usr/bin/env python3
"""Read a written sequence back: the points, the surface as a mesh and the statistics of a dam
break, plotted with matplotlib. Uses only the ghostfx module (no pyopenvdb, no h5py).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/read_sequence.py [FOLDER]

FOLDER holds frames as `ghostfx run examples/dam_break/scene.json` writes them (default
out/python_sequence; when it has no frames, the script simulates the first 12 frames of the
dam break into it first with `ghostfx run`, about 15 s on 2 cores). Per frame it reads liquid_points.$F4.vdb
(read_points), meshes the `surface` level set of liquid.$F4.vdb (mesh_volume, as
outputs.mesh does) and writes the mesh beside it as surface.$F4.obj; then it reads stats.h5
(read_stats). The plot, FOLDER/sequence.png, shows the surge front and the liquid's mean speed
against time, the mesh's enclosed volume against the liquid's rest volume, and the time step.
"""
import glob
import os
import re
import subprocess
import sys

import numpy as np

import ghostfx

HERE = os.path.dirname(os.path.abspath(__file__))
DAM = os.path.join(HERE, "..", "dam_break", "scene.json")


def simulate(folder, frames=12):
    """The dam break's first `frames` frames written into `folder` by `ghostfx run` (the
    program beside the module in a build tree, $GHOSTFX_EXE or the PATH's)."""
    subprocess.run([ghostfx._program(), "run", DAM, "--out", folder, "--frames", f"1-{frames}",
                    "-D", "outputs.preview=false"], check=True)


def write_obj(path, mesh):
    """A Wavefront OBJ of a mesh dict (points, triangles), 1-based faces."""
    with open(path, "w") as f:
        for p in mesh["points"]:
            f.write(f"v {p[0]:.6g} {p[1]:.6g} {p[2]:.6g}\n")
        for t in mesh["triangles"] + 1:
            f.write(f"f {t[0]} {t[1]} {t[2]}\n")


def enclosed_volume(mesh):
    """The volume (m^3) a closed, outward-wound triangle mesh encloses (divergence theorem)."""
    p, t = mesh["points"].astype(np.float64), mesh["triangles"]
    return np.einsum("ij,ij->i", p[t[:, 0]], np.cross(p[t[:, 1]], p[t[:, 2]])).sum() / 6


def read_frames(folder):
    """Per frame: (frame, front x, mean speed, mesh volume)."""
    rows = []
    for points_file in sorted(glob.glob(os.path.join(folder, "liquid_points.*.vdb"))):
        frame = int(re.search(r"\.(\d+)\.vdb$", points_file).group(1))
        points = ghostfx.read_points(points_file)
        speed = np.linalg.norm(points["v"], axis=1)
        volume_file = os.path.join(folder, f"liquid.{frame:04d}.vdb")
        mesh = ghostfx.mesh_volume(volume_file)
        write_obj(os.path.join(folder, f"surface.{frame:04d}.obj"), mesh)
        rows.append((frame, points["P"][:, 0].max(), speed.mean(), enclosed_volume(mesh)))
        print(f"frame {frame}: {len(speed)} particles, front {rows[-1][1]:.3f} m, mean speed "
              f"{rows[-1][2]:.3f} m/s, mesh {len(mesh['triangles'])} triangles enclosing "
              f"{rows[-1][3] * 1e3:.2f} L", flush=True)
    return np.array(rows)


def plot(folder, rows, stats, frame_rate=30.0, rest_volume=0.25 * 0.35 * 0.24):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t = rows[:, 0] / frame_rate
    fig, ax = plt.subplots(1, 3, figsize=(11, 3.2), dpi=110)
    ax[0].plot(t, rows[:, 1], label="front (largest x, m)")
    ax[0].plot(t, rows[:, 2], label="mean speed (m/s)")
    ax[0].set_xlabel("t (s)")
    ax[0].legend()
    ax[1].plot(t, rows[:, 3] / rest_volume, "o-")
    ax[1].set_xlabel("t (s)")
    ax[1].set_ylabel("mesh volume / rest volume")
    ax[2].plot(stats["time"], stats["dt"] * 1e3)
    ax[2].set_xlabel("t (s)")
    ax[2].set_ylabel("step (ms)")
    fig.suptitle("Dam break read back: points, surface mesh and statistics")
    fig.tight_layout()
    png = os.path.join(folder, "sequence.png")
    fig.savefig(png)
    print(f"plot: {png}")


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else os.path.join("out", "python_sequence")
    if not glob.glob(os.path.join(folder, "liquid_points.*.vdb")):
        os.makedirs(folder, exist_ok=True)
        simulate(folder)
    rows = read_frames(folder)
    stats = ghostfx.read_stats(os.path.join(folder, "stats.h5"))
    try:
        plot(folder, rows, stats)
    except ImportError:
        print("matplotlib is not installed (Debian: python3-matplotlib): no plot", file=sys.stderr)


if __name__ == "__main__":
    main()
