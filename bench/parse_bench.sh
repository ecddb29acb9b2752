#!/usr/bin/env bash
# Trajectory CSV parse throughput against `wc -l` on the same file.
# Generates (or reuses) a ~500 MB realistic trajectory CSV with bench_parse,
# warms the page cache, then times `wc -l` and ReadTrajectoryCsv (best of 3
# each) and prints MB/s for both and their ratio, by wall clock and by CPU
# time (the latter is the fair figure on a machine busy with other work).
#   usage: bench/parse_bench.sh [BUILD_DIR]      (default: build)
#   env:   PARSE_BENCH_MB   file size in MB      (default: 500)
#          PARSE_BENCH_DIR  where the file lives (default: $TMPDIR/umbmark_parse_bench)
set -euo pipefail

build_dir=${1:-build}
bench=$build_dir/bench_parse
size_mb=${PARSE_BENCH_MB:-500}
dir=${PARSE_BENCH_DIR:-${TMPDIR:-/tmp}/umbmark_parse_bench}
file=$dir/trajectory_${size_mb}MB.csv

if [[ ! -x $bench ]]; then
  echo "parse_bench.sh: $bench not found; build it first: cmake --build $build_dir --target bench_parse" >&2
  exit 2
fi
mkdir -p "$dir"
if [[ ! -s $file ]]; then
  "$bench" --generate "$file" "$size_mb"
else
  echo "reusing $file"
fi
cat "$file" > /dev/null  # warm the page cache so both tools read from memory

bytes=$(stat -c %s "$file")
lines=$(wc -l < "$file")
# wc -l: best of 3, wall clock and CPU time (user + sys), via bash's `time`.
best_wc_wall="" best_wc_cpu=""
TIMEFORMAT='%3R %3U %3S'
for _ in 1 2 3; do
  read -r real user sys < <({ time wc -l < "$file" > /dev/null; } 2>&1)
  cpu=$(awk -v u="$user" -v s="$sys" 'BEGIN { print u + s }')
  if [[ -z $best_wc_wall ]] || awk -v a="$real" -v b="$best_wc_wall" 'BEGIN { exit !(a < b) }'; then best_wc_wall=$real; fi
  if [[ -z $best_wc_cpu ]] || awk -v a="$cpu" -v b="$best_wc_cpu" 'BEGIN { exit !(a < b) }'; then best_wc_cpu=$cpu; fi
done
mbps() { awk -v b="$bytes" -v s="$1" 'BEGIN { if (s > 0) printf "%.1f", b / 1e6 / s; else print "inf" }'; }
wc_wall=$(mbps "$best_wc_wall")
wc_cpu=$(mbps "$best_wc_cpu")

result=$("$bench" "$file" 3)
parse_wall=$(sed -n 's/.* MB_per_s=\([0-9.]*\).*/\1/p' <<< "$result")
parse_cpu=$(sed -n 's/.*MB_per_cpu_s=\([0-9.]*\).*/\1/p' <<< "$result")

echo "file:   $file ($(awk -v b="$bytes" 'BEGIN { printf "%.1f", b / 1e6 }') MB, $lines lines)"
echo "parser: $result"
echo "wc -l:             $wc_wall MB/s wall, $wc_cpu MB/s CPU time"
echo "ReadTrajectoryCsv: $parse_wall MB/s wall, $parse_cpu MB/s CPU time"
awk -v w="$wc_wall" -v p="$parse_wall" -v wc="$wc_cpu" -v pc="$parse_cpu" \
  'BEGIN { printf "ratio wc -l / parser: %.1f (wall), %.1f (CPU time)\n", w / p, wc / pc }'
