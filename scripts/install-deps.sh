#!/usr/bin/env bash
# Installs exactly the Debian 12 packages ghostfx needs to build, test and benchmark.
# Does nothing (and needs no network or root) when every package is already installed.
# See ../shared/STACK.md for why each one is here (libboost-iostreams-dev is required by
# FindOpenVDB.cmake and the OpenVDB headers but is not a dependency of libopenvdb-dev).
set -euo pipefail

packages=(
    cmake g++ make ninja-build pkg-config ccache
    libopenvdb-dev libboost-iostreams-dev libtbb-dev libeigen3-dev
    libhdf5-dev libopenexr-dev python3-imath
    libgtest-dev libgmock-dev libbenchmark-dev libassimp-dev
    nlohmann-json3-dev libcli11-dev
    python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib
)

# `install-deps.sh --mpi`: also what one simulation over MPI processes needs (-DGHOSTFX_MPI=ON).
if [ "${1:-}" = "--mpi" ]; then
    packages+=(libopenmpi-dev openmpi-bin)
fi

missing=()
for p in "${packages[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$p")
    fi
done

if [ ${#missing[@]} -eq 0 ]; then
    exit 0
fi

echo "install-deps: installing ${#missing[@]} missing package(s): ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
    SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
