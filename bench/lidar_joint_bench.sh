#!/usr/bin/env bash
# Accuracy, interval coverage and speed of `calibrate-lidar`'s joint fit on
# simulated drives (bench/bench_lidar_joint.cpp, tests/support/lidar_sim.hpp):
#   1. BAGS (default 200) five-minute drives, seeds 1..BAGS: RMS and largest
#      error per quantity and the share of bags whose 95 % interval holds the
#      truth (target 93-97 %);
#   2. the same for 50 drives with the lidar upside down (seeds 5001..);
#   3. one 10-minute drive (6,000 scans) pinned to one core: CPU seconds of
#      registration + fit (target <= 10 s), with instantaneous scans and with
#      full-period sweeps (deskewed).
#   bench/lidar_joint_bench.sh [BUILD_DIR]     env: BAGS (200)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
bags=${BAGS:-200}
cmake --build "$build" --target bench_lidar_joint >/dev/null
pin=()
if command -v taskset >/dev/null 2>&1; then pin=(taskset -c 0); fi
echo "== $bags five-minute drives"
"${pin[@]}" "$build/bench_lidar_joint" "$bags" 5 1 --quiet
echo "== 50 five-minute drives, lidar upside down"
"${pin[@]}" "$build/bench_lidar_joint" 50 5 5001 --upside-down --quiet
echo "== one 10-minute drive (6,000 scans), one core"
"${pin[@]}" "$build/bench_lidar_joint" 1 10 9001
echo "== the same drive with full-period sweeps (time_increment set: deskewed), one core"
"${pin[@]}" "$build/bench_lidar_joint" 1 10 9001 --sweep 1
