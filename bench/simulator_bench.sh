#!/usr/bin/env bash
# Monte Carlo engine benchmark: Chong & Kleeman's Table 1 set-up (10^4 runs
# x 10^4 partitions) on one thread and on all cores, next to a plain scalar
# reference loop, then the same through `umbmark predict --monte-carlo`.
# Usage: bench/simulator_bench.sh [BUILD_DIR]   (default: build-bench, Release)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build-bench}"
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --target bench_simulator umbmark -j2 >/dev/null
echo "== bench_simulator (uptime: $(uptime | sed 's/.*load/load/'))"
"$build/bench_simulator"
# The AVX2 kernel (what a CPU without AVX-512 runs), one engine line.
echo "== AVX2 kernel (one thread)"
"$build/bench_simulator" --kernel avx2 --reference-runs 100 --threads 1 2>&1 | grep -m1 "engine" || echo "  (not available)"
robot="$(mktemp --suffix=.toml)"
trap 'rm -f "$robot"' EXIT
printf 'wheelbase_m = 0.4\nwheel_diameter_left_m = 0.1\nwheel_diameter_right_m = 0.1\n' >"$robot"
for t in 1 0; do
  echo "== umbmark predict --monte-carlo 10000 --partitions 10000 --threads $t"
  "$build/umbmark" predict --robot "$robot" --kl 0.001 --kr 0.001 --path arc:3:1 \
    --monte-carlo 10000 --partitions 10000 --threads "$t" | tail -n 1
done
