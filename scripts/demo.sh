#!/usr/bin/env bash
# The default example until the scene runner lands: Poisson-disk sample a sphere and a torus
# ([SB12] Sec. 4.5-4.6) and print the particle statistics.
set -euo pipefail
build=${1:-build}
exe="$build/cmd/ghostfx"
"$exe" --version
"$exe" sample --shape sphere --size 0.1 --spacing 0.01
"$exe" sample --shape torus --size 0.1 --spacing 0.008
