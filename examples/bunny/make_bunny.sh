#!/usr/bin/env bash
# Makes examples/bunny/bunny.vdb, the solid level set of examples/bunny/scene.json:
#   1. installs the npm package `bunny` (the Stanford bunny, 1,839 vertices, 3,674 triangles,
#      public domain) into a scratch folder, out/bunny/npm (not committed);
#   2. writes it as an OBJ in metres: scaled to 0.30 m tall, base on y = 0, centred in x and z;
#   3. converts the OBJ to a narrow-band level set with `ghostfx mesh2sdf` (voxel 5 mm = h / 2).
# Run from the repository root:  examples/bunny/make_bunny.sh [path/to/ghostfx]
set -euo pipefail
ghostfx=${1:-build/cmd/ghostfx}
for tool in node npm; do
    command -v "$tool" >/dev/null || { echo "make_bunny.sh: '$tool' not found: sudo apt-get install -y nodejs npm" >&2; exit 1; }
done
[ -x "$ghostfx" ] || { echo "make_bunny.sh: '$ghostfx' is not an executable ghostfx (build it with make build, or pass its path)" >&2; exit 1; }
here=$(cd "$(dirname "$0")" && pwd)
scratch=out/bunny/npm
mkdir -p "$scratch"
if [ ! -d "$scratch/node_modules/bunny" ]; then
    (cd "$scratch" && npm install --no-audit --no-fund --no-save bunny@1.0.1 >/dev/null)
fi
NODE_PATH="$scratch/node_modules" node - "$scratch/bunny.obj" <<'JS'
const fs = require('fs');
const { positions, cells } = require('bunny');
const height = 0.30;                              // metres
const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
for (const p of positions) for (let i = 0; i < 3; ++i) {
    lo[i] = Math.min(lo[i], p[i]); hi[i] = Math.max(hi[i], p[i]);
}
const s = height / (hi[1] - lo[1]);
const c = [(lo[0] + hi[0]) / 2, lo[1], (lo[2] + hi[2]) / 2];   // base centre -> origin
const lines = ['# Stanford bunny (npm package bunny), metres, base on y = 0'];
for (const p of positions)
    lines.push('v ' + [0, 1, 2].map(i => ((p[i] - c[i]) * s).toFixed(6)).join(' '));
for (const f of cells) lines.push('f ' + f.map(i => i + 1).join(' '));
fs.writeFileSync(process.argv[2], lines.join('\n') + '\n');
console.log(`bunny.obj: ${positions.length} vertices, ${cells.length} triangles, ` +
            `${((hi[0] - lo[0]) * s).toFixed(3)} x ${height.toFixed(3)} x ${((hi[2] - lo[2]) * s).toFixed(3)} m`);
JS
"$ghostfx" mesh2sdf "$scratch/bunny.obj" -o "$here/bunny.vdb" --voxel-size 0.005 --role solid
"$ghostfx" info "$here/bunny.vdb" | grep -E 'voxel size|active voxels|world bounds'
