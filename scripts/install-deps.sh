#!/usr/bin/env bash
# Install the Debian packages fdem needs; quick and silent when they are present.
set -euo pipefail
PKGS=(cmake make g++ pkg-config libopenmpi-dev openmpi-bin libpetsc-real-dev libmetis-dev
      libeigen3-dev libhdf5-openmpi-dev hdf5-tools libyaml-cpp-dev libgtest-dev
      python3 python3-numpy python3-h5py python3-matplotlib python3-yaml python3-jsonschema)
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
