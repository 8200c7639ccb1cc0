#!/usr/bin/env bash
# Install the Debian packages fdem needs; quick and silent when they are present.
set -euo pipefail
PKGS=(cmake make g++ pkg-config libopenmpi-dev openmpi-bin libpetsc-real-dev libmetis-dev
      libeigen3-dev libhdf5-openmpi-dev hdf5-tools libyaml-cpp-dev libgtest-dev
      python3 python3-numpy python3-h5py python3-matplotlib python3-yaml python3-jsonschema)
# Not Debian/Ubuntu (RHEL, a cluster with environment modules): install nothing; say what fdem needs
# and how to build it with plain CMake (README.md#building-elsewhere). With cmake, pkg-config and
# mpicxx on the PATH (modules loaded) exit 0, so that `make build` goes on and CMake's checks name
# anything still missing; else exit 2.
if ! command -v dpkg-query >/dev/null 2>&1 || ! command -v apt-get >/dev/null 2>&1; then
  {
    echo "fdem: this is not a Debian/Ubuntu system (no dpkg-query/apt-get): scripts/install-deps.sh installs nothing here."
    echo "fdem needs (install them or load your site's modules, all built with one MPI):"
    echo "  a C++17 compiler; CMake >= 3.18; pkg-config"
    echo "  MPI-3 (Open MPI, MPICH, ...) with mpicc/mpicxx"
    echo "  PETSc (real scalars, double precision; pkg-config PETSc)"
    echo "  parallel HDF5 built with the same MPI (pkg-config hdf5-openmpi, or cmake -DFDEM_HDF5_PC=<its name>)"
    echo "  METIS 5; Eigen 3 (pkg-config eigen3); yaml-cpp (its CMake package)"
    echo "  GoogleTest (the tests only: cmake -DFDEM_TESTS=OFF builds fdem without it)"
    echo "  Python 3 with numpy, h5py, matplotlib, PyYAML (post-processing; jsonschema for one test)"
    echo "  (Debian's names, for reference: ${PKGS[*]})"
    echo "Then build with plain CMake (README.md#building-elsewhere):"
    echo "  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build -j"
    echo "  (--target fdem: the binary alone; -DFDEM_TESTS=OFF: no GoogleTest; -DFDEM_HDF5_PC=hdf5: a module's HDF5)"
  } >&2
  absent=()
  for t in cmake pkg-config mpicxx; do command -v "$t" >/dev/null 2>&1 || absent+=("$t"); done
  if [ ${#absent[@]} -eq 0 ]; then
    echo "fdem: cmake, pkg-config and mpicxx are on the PATH: going on (CMake's checks name anything missing)." >&2
    exit 0
  fi
  echo "fdem: not on the PATH: ${absent[*]} -- install or load them first." >&2
  exit 2
fi
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "fdem: installing missing Debian packages: ${missing[*]}"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
