#!/usr/bin/env bash
# Installs what dydp needs from Debian's packages, only what is missing.
# Non-interactive and idempotent; run as root (or with sudo available).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config ccache
  libeigen3-dev libsundials-dev libyaml-cpp-dev libcli11-dev
  clang-14 libclang-rt-14-dev
  libgtest-dev libgmock-dev libbenchmark-dev nlohmann-json3-dev
  gnuplot-nox liborocos-kdl-dev
  qt6-base-dev qt6-charts-dev libqt6opengl6-dev libgl-dev
  libboost-dev libopenmpi-dev openmpi-bin
  libzip-dev libxml2-utils
  libmatio-dev pybind11-dev python3-dev python3-numpy python3-pytest python3-scipy python3-matplotlib
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
