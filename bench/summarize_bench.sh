#!/usr/bin/env bash
# `umbmark summarize` of a generated fleet (bench/fleet_gen.sh) of 5,000
# calibrations against 8 as the baseline: wall time and peak resident memory
# (/usr/bin/time -v) of one summarize writing --json, --csv and --report.
# Target (issue 31): 5,000 calibrations under 2 s and 200 MB.
# Usage: summarize_bench.sh BUILD_DIR [N (5000)] [REPEATS (3): the fastest counts]
set -euo pipefail
exe=$(cd "$1" && pwd)/umbmark
n=${2:-5000}
repeats=${3:-3}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf '%-10s %10s %12s %10s %s\n' robots "wall [s]" "peak RSS [MB]" outliers "report [kB]"
for count in 8 "$n"; do
  bash "$here/fleet_gen.sh" "$count" "$tmp/fleet$count" >/dev/null
  best=""
  for ((r = 0; r < repeats; r++)); do
    /usr/bin/time -v "$exe" summarize "$tmp/fleet$count"/*.json --json "$tmp/out.json" --csv "$tmp/out.csv" \
      --report "$tmp/out.html" >/dev/null 2>"$tmp/time.log"
    wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, p, ":"); s = 0; for (i = 1; i <= n; i++) s = s * 60 + p[i]; print s}' "$tmp/time.log")
    rss=$(awk -F': ' '/Maximum resident set size/ {printf "%.1f", $2 / 1024}' "$tmp/time.log")
    if [ -z "$best" ] || awk -v a="$wall" -v b="$best" 'BEGIN {exit !(a < b)}'; then best=$wall; best_rss=$rss; fi
  done
  outliers=$(grep -o '"outliers": *[0-9]*' "$tmp/out.json" | grep -o '[0-9]*$')
  printf '%-10s %10s %12s %10s %s\n' "$count" "$best" "$best_rss" "$outliers" "$(( $(wc -c <"$tmp/out.html") / 1024 ))"
done
