#!/usr/bin/env bash
# Installs the Debian packages umbmark needs (compiler, CMake, Ninja, Eigen,
# Ceres, CLI11, fmt, nlohmann-json, toml++, fast_float, Catch2 v2, Boost.Math,
# NLopt, clang for the fuzz targets; SQLite3, zstd, lz4, ISA-L (CRC-32) for rosbag2
# import; yaml-cpp for the tests of the ROS 2 parameter files; pybind11, numpy,
# pytest, matplotlib for the Python module, its tests and examples). Uses sudo when
# not root. Safe to re-run.
set -euo pipefail
PACKAGES=(build-essential cmake ninja-build pkg-config libeigen3-dev libceres-dev libcli11-dev libfmt-dev
  nlohmann-json3-dev libtomlplusplus-dev libfast-float-dev catch2 clang libclang-rt-dev
  libsqlite3-dev libzstd-dev liblz4-dev libisal-dev libyaml-cpp-dev libboost-math-dev libnlopt-cxx-dev)
PACKAGES+=(pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib)  # the Python module, its tests and examples
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "Installing: ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
