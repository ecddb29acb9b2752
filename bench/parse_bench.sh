#!/usr/bin/env bash
# Trajectory CSV parse throughput against `wc -l` on the same file.
# Generates (or reuses) a ~500 MB realistic trajectory CSV with bench_parse,
# warms the page cache, then times `wc -l` and ReadTrajectoryCsv (best of 3
# each) and prints MB/s for both and their ratio.
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
best_wc=""
for _ in 1 2 3; do
  start=$(date +%s%N)
  lines=$(wc -l < "$file")
  end=$(date +%s%N)
  t=$(( end - start ))
  if [[ -z $best_wc || $t -lt $best_wc ]]; then best_wc=$t; fi
done
wc_mbps=$(awk -v b="$bytes" -v ns="$best_wc" 'BEGIN { printf "%.1f", b / 1e6 / (ns / 1e9) }')

result=$("$bench" "$file" 3)
parse_mbps=$(sed -n 's/.* MB_per_s=\([0-9.]*\).*/\1/p' <<< "$result")
parse_cpu_mbps=$(sed -n 's/.*MB_per_cpu_s=\([0-9.]*\).*/\1/p' <<< "$result")

echo "file:   $file ($(awk -v b="$bytes" 'BEGIN { printf "%.1f", b / 1e6 }') MB, $lines lines)"
echo "parser: $result"
echo "wc -l:          $wc_mbps MB/s"
echo "ReadTrajectoryCsv: $parse_mbps MB/s wall, $parse_cpu_mbps MB/s CPU time"
awk -v w="$wc_mbps" -v p="$parse_mbps" 'BEGIN { printf "ratio wc -l / parser (wall): %.1f\n", w / p }'
