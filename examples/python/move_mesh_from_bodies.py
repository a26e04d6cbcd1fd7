#!/usr/bin/env python3
"""Move a mesh by a dynamic solid's rows of bodies.csv: one OBJ per frame.

A row gives the body's centre of mass x and its orientation q (qw, qx, qy, qz) at a frame; a
point p of the solid's geometry, as the scene gives it, is then at R(q) (p - c) + x, where c is
the centre of mass of the geometry as given. For a uniform body c is the centroid of its
volume, which this script computes from the mesh itself (a closed, consistently wound mesh);
--centre gives it instead.

The mesh is an OBJ file (its v and f lines; other lines are copied unchanged), or with --box
a box generated from its min and max corners (the scene's "box" geometry).

    python3 examples/python/move_mesh_from_bodies.py out/floating_crate/bodies.csv crate \\
        --box 0.45 0.01 0.09 0.57 0.11 0.21 --out out/floating_crate/crate

writes out/floating_crate/crate.0001.obj, crate.0002.obj, ... Needs numpy only.
"""
import argparse
import csv
import sys

import numpy as np


def box_mesh(lo, hi):
    """The OBJ lines of a box (8 vertices, 12 triangles wound outwards)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    # Corner i takes x, y, z from hi where bit 0, 1, 2 of i is set.
    corners = [[(hi if i & 1 else lo)[0], (hi if i & 2 else lo)[1], (hi if i & 4 else lo)[2]]
               for i in range(8)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    lines = ["v %r %r %r" % tuple(c) for c in corners]
    for a, b, c, d in quads:
        lines.append("f %d %d %d" % (a + 1, b + 1, c + 1))
        lines.append("f %d %d %d" % (a + 1, c + 1, d + 1))
    return lines


def read_obj(path):
    with open(path) as f:
        return [line.rstrip("\n") for line in f]


def vertices_and_faces(lines):
    """The vertex positions and the triangles (fans of polygons, 0-based) of OBJ lines."""
    verts, faces = [], []
    for line in lines:
        parts = line.split()
        if parts and parts[0] == "v":
            verts.append([float(x) for x in parts[1:4]])
        elif parts and parts[0] == "f":
            idx = [int(p.split("/")[0]) for p in parts[1:]]
            idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
            faces += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
    return np.array(verts, float), np.array(faces, int)


def centroid(verts, faces):
    """The centre of the volume a closed triangle mesh encloses (signed tetrahedra)."""
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    volumes = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    if abs(volumes.sum()) < 1e-300:
        sys.exit("move_mesh_from_bodies: the mesh encloses no volume: give --centre")
    return (volumes[:, None] * (a + b + c) / 4.0).sum(axis=0) / volumes.sum()


def rotation(qw, qx, qy, qz):
    """The rotation matrix of a unit quaternion."""
    return np.array([
        [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qw * qz), 2 * (qx * qz + qw * qy)],
        [2 * (qx * qy + qw * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qw * qx)],
        [2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), 1 - 2 * (qx * qx + qy * qy)]])


def moved_lines(lines, rot, centre, position):
    """The OBJ lines with every vertex moved: R (p - c) + x."""
    out = []
    for line in lines:
        parts = line.split()
        if parts and parts[0] == "v":
            p = np.array([float(x) for x in parts[1:4]])
            w = rot @ (p - centre) + position
            out.append("v %.9g %.9g %.9g" % tuple(w))
        else:
            out.append(line)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("bodies", help="bodies.csv of a ghostfx run")
    ap.add_argument("name", help="the solid's name in the scene")
    src = ap.add_mutually_exclusive_group(required=True)
    src.add_argument("--obj", help="the solid's mesh, as the scene places its geometry")
    src.add_argument("--box", nargs=6, type=float, metavar=("X0", "Y0", "Z0", "X1", "Y1", "Z1"),
                     help="a box from its min and max corners")
    ap.add_argument("--centre", nargs=3, type=float, help="centre of mass of the geometry as given")
    ap.add_argument("--out", required=True, help="output prefix: PREFIX.0001.obj, ...")
    args = ap.parse_args()

    lines = read_obj(args.obj) if args.obj else box_mesh(args.box[:3], args.box[3:])
    centre = np.array(args.centre) if args.centre else centroid(*vertices_and_faces(lines))
    written = 0
    with open(args.bodies, newline="") as f:
        for row in csv.DictReader(f):
            if row["name"] != args.name:
                continue
            q = [float(row[k]) for k in ("qw", "qx", "qy", "qz")]
            x = np.array([float(row[k]) for k in ("x", "y", "z")])
            path = "%s.%04d.obj" % (args.out, int(row["frame"]))
            with open(path, "w") as out:
                out.write("\n".join(moved_lines(lines, rotation(*q), centre, x)) + "\n")
            written += 1
    if written == 0:
        sys.exit("move_mesh_from_bodies: '%s' has no rows of '%s'" % (args.bodies, args.name))
    print("wrote %d meshes %s.NNNN.obj (centre of mass of the geometry %s)"
          % (written, args.out, np.array2string(centre, precision=4)))


if __name__ == "__main__":
    main()
