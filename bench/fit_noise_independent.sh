#!/usr/bin/env bash
# fit-noise on INDEPENDENT campaigns of uncalibrated robots (issue 22 item
# 3): campaigns from bench/indep_campaign.cpp (its own 1 kHz physics, a
# closed-loop controller on the odometry, written from the contract, no
# code shared with lib/simulation or lib/error_models), fitted by
# `umbmark fit-noise` with its defaults. Prints, over the 2N intervals
# (k_L and k_R of N campaigns):
#   - how many 95 % intervals hold the true k (target >= 0.85 of them),
#   - the mean signed relative error of k (target |.| <= 5 %),
#   - the rms of the z-scores (target <= 1.4), z = ln(k_hat / k_true) / s,
#     s = the interval's half-width in ln k on the side of the truth / 1.96
#     (so |z| <= 1.96 exactly when the interval holds the truth).
#
# Per campaign (uniform unless stated, drawn by awk from SEED):
#   robot   wheelbase 0.3-0.5 m, wheel diameter 0.08-0.15 m, NOT calibrated:
#           E_d = 1 +- 0.3-1 %, E_b = 1 +- 1-3 %; k_L, k_R log-uniform
#           5e-4-2e-3 m^1/2 each; ground truth 0.2-0.5 mm, 1-2 mrad (in the
#           manifest)
#   motion  squares 2-3 m (10 cw + 10 ccw), back-and-forth 2-4 m (20 runs),
#           0.2-0.4 m/s, spot turns 0.6-1.2 rad/s; free paths none or 10
#   design  10 / 20 / 50 Hz; 500 / 4096 / 20000 ticks per revolution; pauses
#           0 or 1 s; acceleration limit none or 0.3-1 m/s^2; heading hold
#           none or 1-3 1/s
#
# Usage: bench/fit_noise_independent.sh [BUILD_DIR [N [SEED [FIT-NOISE ARGS...]]]]
#   (default build, 20 campaigns, seed 2202). Extra arguments go to fit-noise
#   (e.g. --systematic none). Per-campaign lines, then the three figures.
set -euo pipefail
BUILD=${1:-build}
N=${2:-20}
SEED=${3:-2202}
shift $(( $# < 3 ? $# : 3 ))
UMBMARK="$BUILD/umbmark"
GEN="$BUILD/indep_campaign"
for exe in "$UMBMARK" "$GEN"; do
  [[ -x "$exe" ]] || { echo "missing $exe (build the umbmark and indep_campaign targets)" >&2; exit 2; }
done
command -v jq >/dev/null || { echo "this bench needs jq" >&2; exit 2; }
OUT=$(mktemp -d "${TMPDIR:-/tmp}/umbmark-fitnoise-indep.XXXXXX")
echo "seed $SEED, $N campaigns, fit-noise $*; campaigns in $OUT"

awk -v n="$N" -v seed="$SEED" '
function U(a, b) { return a + (b - a) * rand() }
function S() { return rand() < 0.5 ? -1 : 1 }
function LU(a, b) { return exp(U(log(a), log(b))) }
BEGIN {
  srand(seed)
  for (id = 0; id < n; ++id) {
    b = U(0.3, 0.5); d = U(0.08, 0.15); kl = LU(5e-4, 2e-3); kr = LU(5e-4, 2e-3)
    gxy = U(2e-4, 5e-4); gth = U(1e-3, 2e-3); side = U(2, 3); dist = U(2, 4); v = U(0.2, 0.4); w = U(0.6, 1.2)
    rates[1] = 10; rates[2] = 20; rates[3] = 50; rate = rates[int(rand() * 3) + 1]
    tk[1] = 500; tk[2] = 4096; tk[3] = 20000; ticks = tk[int(rand() * 3) + 1]
    pause = rand() < 0.5 ? 0 : 1
    accel = rand() < 0.5 ? 0 : U(0.3, 1.0)
    hold = rand() < 0.5 ? 0 : U(1, 3)
    ed = 1 + S() * U(0.003, 0.01); eb = 1 + S() * U(0.01, 0.03)
    free = rand() < 0.5 ? 0 : 10
    printf "%03d %.6g %.6g --seed %d --wheelbase %.6g --diameter %.6g --kl %.6g --kr %.6g --gt-sigma-xy %.6g --gt-sigma-theta %.6g --side %.6g --distance %.6g --speed %.6g --turn-rate %.6g --rate %d --ticks %d --pause %d --accel %.6g --heading-hold %.6g --free %d --E-d %.8g --E-b %.8g\n", \
      id, kl, kr, seed * 1000 + id, b, d, kl, kr, gxy, gth, side, dist, v, w, rate, ticks, pause, accel, hold, free, ed, eb
  }
}' > "$OUT/cases.txt"

printf '%-4s %-9s %-9s %-31s %-9s %-31s %s\n' id k_L_true k_L "interval" k_R_true k_R "interval (design)"
: > "$OUT/table.txt"
while read -r id kl kr args; do
  dir="$OUT/$id"
  # shellcheck disable=SC2086
  "$GEN" --out "$dir/campaign" $args
  if ! "$UMBMARK" fit-noise "$dir/campaign/campaign.toml" --json "$dir/fit.json" "$@" > "$dir/report.txt" 2>&1; then
    echo "$id fit-noise failed: $(tail -1 "$dir/report.txt")"
    echo "$kl $kr nan nan nan nan nan nan" >> "$OUT/table.txt"
    continue
  fi
  row=$(jq -r '[.k_L, .k_L_ci95[0], (.k_L_ci95[1] // 1e300), .k_R, .k_R_ci95[0], (.k_R_ci95[1] // 1e300)] | @tsv' "$dir/fit.json")
  echo "$kl $kr $row" >> "$OUT/table.txt"
  read -r a lo hi c lo2 hi2 <<< "$row"
  design=$(awk '{for (i = 1; i < NF; ++i) if ($i ~ /^--(rate|ticks|pause|accel|heading-hold|free|E-d|E-b)$/) printf "%s=%s ", substr($i, 3), $(i + 1)}' <<< "$args")
  printf '%-4s %-9.3g %-9.3g [%-9.3g %9.3g] %9s %-9.3g %-9.3g [%-9.3g %9.3g] (%s)\n' "$id" "$kl" "$a" "$lo" "$hi" "" "$kr" "$c" "$lo2" "$hi2" "$design"
done < "$OUT/cases.txt"

awk '
function one(t, k, lo, hi,   z, s) {
  if (k != k + 0 || k == "nan") { ++failed; return }
  ++n; inside += (lo <= t && t <= hi); err += k / t - 1
  if (t >= k) s = (hi >= 1e299) ? 1e300 : (log(hi) - log(k)) / 1.96
  else s = (lo <= 0) ? 1e300 : (log(k) - log(lo)) / 1.96
  z = s > 0 ? log(k / t) / s : 0; zz += z * z
}
{ one($1, $3, $4, $5); one($2, $6, $7, $8) }
END {
  printf "\nintervals holding the truth: %d/%d (target >= %d)\n", inside, n + failed, int(0.85 * (n + failed) + 0.999)
  printf "mean signed error of k:      %+.1f %% (target within +-5 %%)\n", n ? 100 * err / n : 0
  printf "rms of z-scores:             %.2f (target <= 1.4)\n", n ? sqrt(zz / n) : 0
  if (failed) printf "failed fits:                 %d\n", failed
}' "$OUT/table.txt"
