#!/usr/bin/env bash
# The bit-identity check of a refactoring (issue 55's invariant): the example scenes run for a
# few frames at 1 and 2 threads, their checkpoints compared with h5diff (Debian's hdf5-tools)
# against a capture made before the change. A checkpoint holds every particle channel and solver
# scalar, so equal checkpoints mean an equal state; the frame files are built from it.
#
#   scripts/bit-identity.sh capture BUILD DIR    run the scenes with BUILD/cmd/ghostfx into DIR
#   scripts/bit-identity.sh compare DIR_A DIR_B  h5diff every checkpoint of A against B's
#
# EXCLUDE="PATH ..." leaves those HDF5 paths out of the comparison (h5diff --exclude-path), for a
# change that adds a dataset on purpose, e.g. EXCLUDE=/particles/scalar/birth_time against a
# capture made before particles kept their birth time.
# Capture with the build of the commit before the change, then with the change, and compare.
set -euo pipefail
cd "$(dirname "$0")/.."

# name | scene | frames | overrides
SCENES=(
  "dam_tait|examples/dam_break/scene.json|1-6|"
  "dam_dfsph|examples/dam_break/scene.json|1-6|-D settings.pressure=dfsph"
  "dam_basic|examples/dam_break/scene.json|1-4|-D settings.method=basic -D settings.cfl=0.2"
  "double_dam|examples/double_dam_break/scene.json|1-3|"
  "tomato|examples/tomato/scene.json|1-4|"
  "gas_plume|examples/gas_plume/scene.json|1-6|"
  "boiling_pan|examples/boiling_pan/scene.json|1-4|"
)

capture() {
    local exe=$1/cmd/ghostfx dir=$2
    mkdir -p "$dir"
    for entry in "${SCENES[@]}"; do
        IFS='|' read -r name scene frames overrides <<< "$entry"
        for threads in 1 2; do
            local out=$dir/$name.t$threads
            rm -rf "$out"
            # shellcheck disable=SC2086
            "$exe" run "$scene" --frames "$frames" --threads "$threads" --out "$out" -q \
                --sample-cache off --serial-output -D outputs.preview=false \
                -D 'outputs.checkpoint={"file": "state.$F4.h5", "every": 2}' $overrides
            echo "captured $name at $threads threads: $(ls "$out"/state.*.h5 | wc -l) checkpoints"
        done
    done
}

compare() {
    local a=$1 b=$2 failed=0 n=0
    for file in "$a"/*/state.*.h5; do
        local other=$b/${file#"$a"/}
        n=$((n + 1))
        if [ ! -e "$other" ]; then
            echo "missing in $b: ${file#"$a"/}"; failed=1; continue
        fi
        # The whole file: particles, scalars and the header (the scene's settings as canonical
        # JSON, the frame, the counts). h5diff reports datasets of another shape as "not
        # comparable" with exit status 0, so -c lists them and any such line is a difference
        # (but two empty ones: the phase transition's state holds no particles).
        local report status=0 excludes=()
        for path in ${EXCLUDE:-}; do excludes+=(--exclude-path "$path"); done
        report=$(h5diff -c "${excludes[@]}" "$file" "$other" 2>&1) || status=$?
        if [ "$status" != 0 ] || grep -i "not comparable" <<< "$report" | grep -qv "empty dataset"; then
            echo "differs: ${file#"$a"/}"; failed=1
        fi
    done
    [ "$failed" = 0 ] && echo "bit for bit: $n checkpoints of $a and $b"
    return $failed
}

case "${1:-}" in
    capture) capture "$2" "$3" ;;
    compare) compare "$2" "$3" ;;
    *) sed -n '2,10p' "$0"; exit 2 ;;
esac
