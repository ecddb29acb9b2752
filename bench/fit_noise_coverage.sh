#!/usr/bin/env bash
# fit-noise validation table (issue 13 part 3): coverage of the 95 %
# intervals and bias of k_L, k_R over simulated campaigns of an
# uncalibrated robot (E_d in [0.99, 1.01], E_b in [0.97, 1.03]); seeds and
# set-up in bench/fit_noise_coverage.cpp. Then the cost of one fit on many
# runs (likelihood passes, time, peak memory).
# Usage: bench/fit_noise_coverage.sh [BUILD_DIR [CAMPAIGNS]]   (default build-bench, 1000)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build-bench}"
n="${2:-1000}"
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --target fit_noise_coverage umbmark -j2 >/dev/null
echo "== coverage over $n campaigns, 60 runs of 10 m forward and back (uptime: $(uptime | sed 's/.*load/load/'))"
echo "| systematic errors | likelihood | campaigns | coverage k_L (miss low/high) | coverage k_R | bias k_L | bias k_R | failed | s |"
echo "|---|---|---|---|---|---|---|---|---|"
"$build/fit_noise_coverage" ignored "$n" 0.01 0.03 reml
"$build/fit_noise_coverage" given "$n" 0.01 0.03 reml
"$build/fit_noise_coverage" estimated "$n" 0.01 0.03 reml
"$build/fit_noise_coverage" estimated "$n" 0.01 0.03 ml
"$build/fit_noise_coverage" estimated "$n" 0 0 reml
