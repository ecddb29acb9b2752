#!/usr/bin/env bash
# Speed and memory of `import rosbag2 --scan`: generates a recording of
# MINUTES (default 10) of room-A squares with /scan at 10 Hz (360 beams,
# 6,000 scans for 10 minutes) outside the repository, then runs
# build/bench_scan on it under /usr/bin/time -v (peak memory), pinned to one
# core (taskset -c 0 when present); then the same on a recording a third as
# long, so the peak memory of both shows whether it grows with the length.
# Deletes the recordings.
#   bench/scan_bench.sh [BUILD_DIR]     env: BENCH_DIR (/tmp), MINUTES (10)
# Needs node + npm (installs tests/data/rosbag2/generator's pinned packages).
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${BENCH_DIR:-/tmp}
minutes=${MINUTES:-10}
build=${1:-build}
gen=tests/data/rosbag2/generator
[ -d "$gen/node_modules" ] || (cd "$gen" && npm ci --no-audit --no-fund)
cmake --build "$build" --target bench_scan >/dev/null
work=$(mktemp -d "$dir/umbmark-bench-scan.XXXXXX")
trap 'rm -rf "$work"' EXIT
pin=()
if command -v taskset >/dev/null 2>&1; then pin=(taskset -c 0); fi
for m in "$minutes" "$(python3 -c "print(max(1, round($minutes / 3)))")"; do
  node "$gen/scan_gen.mjs" --bench "$work/bench_$m.mcap" "$m"
  /usr/bin/time -v "${pin[@]}" "$build/bench_scan" "$work/bench_$m.mcap" tests/data/rosbag2/scan/robot_a.toml 1.0 \
    2>"$work/time.txt"
  rss=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$work/time.txt")
  echo "  $m minutes: peak memory $((rss / 1024)) MB ($(du -m "$work/bench_$m.mcap" | cut -f1) MB recording)"
done
