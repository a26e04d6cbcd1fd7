#!/usr/bin/env bash
# Install ghostfx from the build tree into a temporary prefix, then configure, build and run a
# tiny project that finds it with find_package(ghostfx).
# Usage: run_consumer_test.sh BUILD_DIR WORK_DIR [SANITIZE]
# With SANITIZE=ON (a sanitizer build of ghostfx) the consumer is built with the same sanitizers,
# since the ASan runtime must come first in the program's library list.
set -euo pipefail
build="$1"
work="$2"
sanitize="${3:-OFF}"
flags=()
if [ "$sanitize" = "ON" ]; then
    flags=(-DCMAKE_CXX_FLAGS="-fsanitize=address,undefined" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined")
fi
here="$(cd "$(dirname "$0")" && pwd)"
rm -rf "$work"
mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
# The installed program runs from the prefix without LD_LIBRARY_PATH (install RPATH), also when
# the environment points elsewhere.
env -u LD_LIBRARY_PATH "$work/prefix/bin/ghostfx" --version | grep -q "^ghostfx "
# The study plot script, where the installed program looks for it (share/ghostfx).
test -x "$work/prefix/share/ghostfx/plot_study.py"
# The Python module, where it was built (not under the sanitizers): importable from the prefix's
# dist-packages, finding the libraries through its install RPATH.
module="$(find "$work/prefix" -name '_ghostfx*.so' | head -n 1)"
if [ -n "$module" ]; then
    env -u LD_LIBRARY_PATH PYTHONPATH="$(dirname "$(dirname "$module")")" /usr/bin/python3 \
        -c "import ghostfx; assert ghostfx.__version__"
fi
generator=()
command -v ninja > /dev/null && generator=(-G Ninja)
cmake -S "$here/consumer" -B "$work/build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$work/prefix" "${flags[@]}" > "$work/configure.log"
cmake --build "$work/build" > "$work/build.log"
LD_LIBRARY_PATH="$work/prefix/lib:${LD_LIBRARY_PATH:-}" "$work/build/consumer" "$work/points.vdb"
test -s "$work/points.vdb"
