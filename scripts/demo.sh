#!/usr/bin/env bash
# The default example: a dam break (examples/dam_break) run to a VDB sequence with previews,
# then a description of the last frame. Outputs land in out/dam_break/.
set -euo pipefail
build=${1:-build}
exe="$build/cmd/ghostfx"
"$exe" --version
"$exe" run examples/dam_break/scene.json
last=$(ls out/dam_break/liquid.*.vdb | tail -1)
"$exe" info "$last"
echo "demo: frames in out/dam_break/ (liquid.*.vdb volumes, liquid_points.*.vdb points, preview.*.exr)"
