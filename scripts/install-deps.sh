#!/usr/bin/env bash
# Installs the Debian packages wedge builds and tests with, only those that are missing.
# Idempotent and quiet when everything is present, so `make` can call it on every run.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libembree-dev libtbb-dev libopenexr-dev libpng-dev libjpeg-dev libtinyobjloader-dev
  nlohmann-json3-dev libcli11-dev libfftw3-dev libgtest-dev libbenchmark-dev
  chromium
  python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib
  clang libclang-rt-14-dev llvm
  libopenmpi-dev openmpi-bin
)
# chromium: the headless browser the experiment-report test screenshots (tests/experiment_test.cpp).
# python3-dev, pybind11-dev: the Python module (python/); numpy for its arrays; pytest runs its
# tests under ctest; matplotlib draws the figures of examples/.
# clang, libclang-rt-14-dev (its sanitizer and libFuzzer runtimes; only recommended by clang, and
# recommends are not installed here) and llvm (llvm-symbolizer, for the sanitizers' stack
# traces): `make test-sanitize` and `make fuzz`.
# libopenmpi-dev, openmpi-bin: Open MPI, so that the same binary runs under `mpirun -n N`
# (docs/mpi.md); without mpirun it is one process as before.
# Optional extras: `WEDGE_EXTRAS=1` adds Embree's path tracer used as the throughput peer in bench/.
if [[ "${WEDGE_EXTRAS:-0}" == 1 ]]; then
  packages+=(embree-tools)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

echo "wedge: installing missing packages: ${missing[*]}" >&2
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "wedge: need root or sudo to apt-get install ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
