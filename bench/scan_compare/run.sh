#!/usr/bin/env bash
# Builds scan_compare against MRPT (libmrpt-slam-dev) and Open3D
# (libopen3d-dev), which the product does not use, and runs it on the
# committed room A recording and, when given, more recordings with their
# lidar mounts.   bench/scan_compare/run.sh [BUILD_DIR] [BAG X,Y,YAW]...
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}; shift || true
cmake --build "$build" --target umbmark_lib >/dev/null
out="$build/scan_compare"
# MRPT 2.5 in Debian ships one include folder per module and no pkg-config
# file; Open3D's pkg-config says -std=c++14, which the C++20 build replaces.
mrpt_inc=(); for d in /usr/include/mrpt/*/include; do mrpt_inc+=(-isystem "$d"); done
mrpt_lib=(); for m in slam maps obs poses tfest math bayes graphs opengl img io serialization rtti containers config \
  system expr random core; do [ -f "/usr/lib/x86_64-linux-gnu/libmrpt-$m.so" ] && mrpt_lib+=("-lmrpt-$m"); done
# shellcheck disable=SC2046
g++ $(pkg-config --cflags Open3D | sed 's/-std=c++[0-9]*//') -O2 -std=c++20 -Ilib -isystem /usr/include/eigen3 \
  "${mrpt_inc[@]}" bench/scan_compare/scan_compare.cpp -o "$out" "$build/libumbmark.a" "${mrpt_lib[@]}" \
  $(pkg-config --libs Open3D) -lfmt -ltomlplusplus -lsqlite3 -lisal -lzstd -llz4
echo "| method | pairs | n | RMS position error [mm] | RMS heading error [mrad] | failures | us per pair |"
echo "|---|---|---|---|---|---|---|"
"$out" tests/data/rosbag2/scan/room_a.mcap 0.12,0,0
while [ $# -ge 2 ]; do "$out" "$1" "$2"; shift 2; done
