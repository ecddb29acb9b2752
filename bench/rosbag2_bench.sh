#!/usr/bin/env bash
# Import benchmark for `import rosbag2`: generates a recording of at least
# 1 GB outside the repository (zstd chunks; JointState 100 Hz, PoseStamped
# 120 Hz, 160x120 rgb8 images of random bytes 30 Hz), then imports it with build/bench_rosbag2
# and decodes the same two topics with the Node reader (@mcap/core +
# @foxglove/rosmsg2-serialization), each under /usr/bin/time -v, and prints
# MB/s, messages/s, peak memory and the ratios. Deletes the recording.
#   bench/rosbag2_bench.sh [BUILD_DIR]     env: BENCH_DIR (/tmp), BENCH_MB (1100)
# Needs node + npm (installs tests/data/rosbag2/generator's pinned packages).
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${BENCH_DIR:-/tmp}
mb=${BENCH_MB:-1100}
build=${1:-build}
gen=tests/data/rosbag2/generator
free_mb=$(df -Pm "$dir" | awk 'NR==2 {print $4}')
if (( free_mb < mb * 2 )); then echo "bench_rosbag2: $dir has $free_mb MB free, need $((mb * 2))" >&2; exit 1; fi
[ -d "$gen/node_modules" ] || (cd "$gen" && npm ci --no-audit --no-fund)
cmake --build "$build" --target bench_rosbag2 >/dev/null
bag=$(mktemp -d "$dir/umbmark-bench-rosbag2.XXXXXX")
trap 'rm -rf "$bag"' EXIT
node "$gen/gen.mjs" --bench "$bag/bench.mcap" "$mb"

run() {  # label, command...: prints the command's line and its peak RSS
  local label=$1; shift
  /usr/bin/time -v "$@" 2>"$bag/time.txt" | tee "$bag/$label.txt"
  local rss wall
  rss=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$bag/time.txt")
  wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {print $2}' "$bag/time.txt")
  echo "  $label: peak memory $((rss / 1024)) MB, wall $wall"
  echo "$rss" >"$bag/$label.rss"
}
echo "== $(du -m "$bag/bench.mcap" | cut -f1) MB recording; page cache warmed by a first read"
cat "$bag/bench.mcap" >/dev/null
run umbmark "$build/bench_rosbag2" "$bag/bench.mcap" tests/data/rosbag2/robot.toml
run node node "$gen/baseline.mjs" "$bag/bench.mcap"
python3 - "$bag" <<'PY'
import re, sys
d = sys.argv[1]
def rates(name):
    t = open(f"{d}/{name}.txt").read()
    return [float(x) for x in re.findall(r"= ([0-9.]+) (?:MB/s|messages/s)", t)]
u, n = rates("umbmark"), rates("node")
ur, nr = int(open(f"{d}/umbmark.rss").read()), int(open(f"{d}/node.rss").read())
print(f"ratio umbmark/node: {u[0] / n[0]:.1f}x MB/s, {u[1] / n[1]:.1f}x messages/s; "
      f"peak memory {ur / 1024:.0f} MB vs {nr / 1024:.0f} MB")
PY
