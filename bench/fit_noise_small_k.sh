#!/usr/bin/env bash
# fit-noise when one wheel's noise is much smaller than the other's (issue
# 30 item 4): N campaigns of `umbmark simulate data/examples/simulate.toml`
# (b = 0.2 m, 1 m squares, 2 m back-and-forth, figure eights, ground truth
# 0.5 mm / 2 mrad) with k_L = 3e-4, k_R = 1e-3 m^1/2, 20 + 20 squares and 40
# back-and-forth runs, seeds SEED+1 .. SEED+N; each fitted by `umbmark
# fit-noise` with its defaults. Prints the mean of (k_hat / k)^2 per wheel
# with its standard error (the bias in k^2, which REML estimates without
# bias to first order), the intervals' coverage and the mean of k_hat / k.
#
# Usage: bench/fit_noise_small_k.sh [BUILD_DIR [N [SEED [SIMULATE ARGS...]]]]
#   (default build, 40 campaigns, seed 1000; e.g. `--gt-sigma-xy 0
#   --gt-sigma-theta 0` without ground-truth noise).
set -euo pipefail
BUILD=${1:-build}
N=${2:-40}
SEED=${3:-1000}
shift $(( $# < 3 ? $# : 3 ))
ROOT=$(cd "$(dirname "$0")/.." && pwd)
[[ -x "$BUILD/umbmark" ]] || { echo "missing $BUILD/umbmark" >&2; exit 2; }
command -v jq >/dev/null || { echo "this bench needs jq" >&2; exit 2; }
OUT=$(mktemp -d "${TMPDIR:-/tmp}/umbmark-small-k.XXXXXX")
trap 'rm -rf "$OUT"' EXIT
KL=3e-4 KR=1e-3
for i in $(seq 1 "$N"); do
  "$BUILD/umbmark" simulate "$ROOT/data/examples/simulate.toml" --out "$OUT/c" --force --seed $((SEED + i)) \
    --kl $KL --kr $KR --square-runs 20 --back-and-forth-runs 40 "$@" > /dev/null 2>&1 || { echo fail; continue; }
  "$BUILD/umbmark" fit-noise "$OUT/c/campaign.toml" --json - 2>/dev/null |
    jq -r '"\(.k_L) \(.k_R) \(.k_L_ci95[0]) \(.k_L_ci95[1]) \(.k_R_ci95[0]) \(.k_R_ci95[1])"' || echo fail
done | awk -v TL=$KL -v TR=$KR '
  /fail/ { f++; next }
  { n++; qL = ($1 / TL)^2; qR = ($2 / TR)^2; sL += qL; sL2 += qL * qL; sR += qR; sR2 += qR * qR
    cL += ($3 <= TL && TL <= $4); cR += ($5 <= TR && TR <= $6); kl += $1 / TL; kr += $2 / TR }
  END { mL = sL / n; mR = sR / n
    printf "%d campaigns (%d failed), seeds %d..%d\n", n, f, '"$SEED"' + 1, '"$SEED"' + n + f
    printf "k_L^2 / true %.3f +- %.3f   k_R^2 / true %.3f +- %.3f   (mean +- standard error)\n",
      mL, sqrt((sL2 / n - mL * mL) / (n - 1)), mR, sqrt((sR2 / n - mR * mR) / (n - 1))
    printf "coverage of the 95 %% intervals: k_L %d/%d, k_R %d/%d;  mean k_hat / k: %.3f, %.3f\n", cL, n, cR, n, kl / n, kr / n }'
