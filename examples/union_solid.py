#!/usr/bin/python3
"""Union of a liquid frame's surface with a solid's level set, for a preview that shows both.

The ghostfx previews render one grid, the liquid; this writes a .vdb whose 'surface' is the
union (min) of the liquid's 'surface' and the solid, to be rendered with `ghostfx preview`.
Needs Debian's python3 with python3-openvdb (run it as /usr/bin/python3).

    /usr/bin/python3 examples/union_solid.py out/bunny/liquid.0020.vdb examples/bunny/bunny.vdb out/bunny/with_bunny.0020.vdb
    /usr/bin/python3 examples/union_solid.py out/tomato/liquid.0030.vdb sphere:0,0.35,0,0.06 out/tomato/with_tomato.0030.vdb
    build/cmd/ghostfx preview out/bunny/with_bunny.0020.vdb --grid surface -o bunny.exr   # or -o x.png
"""
import sys
import pyopenvdb as vdb


def main(liquid_path, solid, out_path):
    liquid = vdb.read(liquid_path, 'surface')
    vs = liquid.transform.voxelSize()[0]
    if solid.startswith('sphere:'):
        cx, cy, cz, r = (float(v) for v in solid[len('sphere:'):].split(','))
        shape = vdb.createLevelSetSphere(radius=r, center=(cx, cy, cz), voxelSize=vs,
                                         halfWidth=liquid.background / vs)
    else:
        path, _, grid = solid.partition(':')
        shape = vdb.read(path, grid or 'surface')
        if abs(shape.transform.voxelSize()[0] - vs) > 1e-6 * vs:
            sys.exit(f'union_solid: voxel size {shape.transform.voxelSize()[0]} of {path} '
                     f'differs from the liquid\'s {vs}')
    out = liquid.deepCopy()
    out.combine(shape, lambda a, b: min(a, b))
    out.name = 'surface'
    vdb.write(out_path, grids=[out])


if __name__ == '__main__':
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*sys.argv[1:])
