#!/usr/bin/env bash
# Installs, with apt-get, every Debian 12 package stereorig needs to build,
# test and run, and only those that are missing. Run as root.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libceres-dev libsuitesparse-dev
  libmrcal-dev mrcal python3 python3-mrcal python3-numpy python3-scipy
  libopencv-dev python3-opencv libtbb-dev
  libapriltag-dev
  libyaml-cpp-dev libcli11-dev libsqlite3-dev libnanoflann-dev nlohmann-json3-dev zlib1g-dev libpng-dev libtiff-dev
  googletest libgtest-dev
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}"
