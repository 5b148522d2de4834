#!/usr/bin/env bash
# Install the Debian 12 packages pointmech builds and runs with.  Idempotent:
# packages already present are left alone.  Needs root (or sudo).
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  liblapacke-dev libopenblas-dev
  libgmsh-dev
  libcgal-dev
  libhdf5-dev
  libyaml-dev
  libmatheval-dev
  libcmocka-dev
  libtiff-dev
  libpetsc-real-dev
  libscotch-dev
  calculix-ccx
  clang-format python3-matplotlib python3-numpy python3-h5py python3-scipy
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" \
    || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
