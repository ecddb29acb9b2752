#!/usr/bin/env bash
# fit-noise on many runs (issue 22 item 5): wall time and peak memory
# (/usr/bin/time -v, maximum resident set size) of `umbmark fit-noise` on N
# trajectory runs of 2 rows each, in the default mode (systematic errors
# estimated jointly) and with --systematic none. Targets for N = 10^6:
# <= 1 GB and <= 20 s on a busy 2-core machine.
#
# The runs (written once by awk, seed 22): a robot with wheelbase 0.4 m,
# wheels of 0.1 m, 4096 ticks per revolution, E_d = 1.004, E_b = 1.01;
# each run drives one arc of 1-2 m (curvature -0.5..0.5 1/m, forward) from
# rest, simulated in 16 pieces in each of which the wheels slip by
# N(0, k^2 |travel|) (k_L = 0.0008, k_R = 0.0012 m^1/2); the ground truth
# (0.3 mm, 1 mrad noise) at the start and the end. Directions alternate "a" and "b" (two groups).
#
# Usage: bench/fit_noise_scale.sh [BUILD_DIR [N]]   (default build, 1000000)
set -euo pipefail
BUILD=${1:-build}
N=${2:-1000000}
UMBMARK="$BUILD/umbmark"
[[ -x "$UMBMARK" ]] || { echo "missing $UMBMARK (build the umbmark target)" >&2; exit 2; }
[[ -x /usr/bin/time ]] || { echo "this bench needs /usr/bin/time (GNU time)" >&2; exit 2; }
OUT=${TMPDIR:-/tmp}/umbmark-fitnoise-scale-$N
mkdir -p "$OUT"
cat > "$OUT/robot.toml" <<'EOF'
wheelbase_m = 0.4
wheel_diameter_left_m = 0.1
wheel_diameter_right_m = 0.1
ticks_per_rev = 4096
EOF
if [[ ! -s "$OUT/runs.csv" ]]; then
  awk -v n="$N" 'BEGIN {
    srand(22); pi = 3.141592653589793; b = 0.4; D = 0.1; tpr = 4096; m = 16
    Ed = 1.004; Eb = 1.01; kl = 0.0008; kr = 0.0012
    cl = 2 / (Ed + 1); cr = 2 * Ed / (Ed + 1)
    print "run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad"
    for (i = 1; i <= n; ++i) {
      s = 1 + rand(); kap = rand() - 0.5
      tl = int((s * (1 - kap * b / 2)) / (pi * D) * tpr + 0.5); tr = int((s * (1 + kap * b / 2)) / (pi * D) * tpr + 0.5)
      # The true robot in m pieces, each wheel slipping independently in each.
      x = 0; y = 0; th = 0
      for (j = 0; j < m; ++j) {
        L = cl * tl * pi * D / tpr / m; R = cr * tr * pi * D / tpr / m
        L += kl * sqrt(L) * N(); R += kr * sqrt(R) * N()
        dth = (R - L) / (Eb * b); ds = (L + R) / 2
        if (dth * dth > 1e-18) { x += ds / dth * (sin(th + dth) - sin(th)); y += ds / dth * (cos(th) - cos(th + dth)) }
        else { x += ds * cos(th); y += ds * sin(th) }
        th += dth
      }
      dir = i % 2 ? "a" : "b"
      printf "%d,%s,0,0,0,%.6g,%.6g,%.6g\n", i, dir, 3e-4 * N(), 3e-4 * N(), 1e-3 * N()
      printf "%d,%s,5,%d,%d,%.9g,%.9g,%.9g\n", i, dir, tl, tr, x + 3e-4 * N(), y + 3e-4 * N(), th + 1e-3 * N()
    }
  }
  function N(   u, v) { u = rand(); v = rand(); if (u < 1e-300) u = 1e-300; return sqrt(-2 * log(u)) * cos(2 * pi * v) }' > "$OUT/runs.csv.tmp"
  mv "$OUT/runs.csv.tmp" "$OUT/runs.csv"
fi
echo "== fit-noise on $N runs of 2 rows ($(du -h "$OUT/runs.csv" | cut -f1)); $(nproc) cores, $(uptime | sed 's/.*load/load/')"
echo "| mode | wall [s] | user+sys [s] | peak RSS [MB] | k_L | k_R | likelihood passes |"
echo "|---|---|---|---|---|---|---|"
for mode in estimate none; do
  /usr/bin/time -v "$UMBMARK" fit-noise "$OUT/runs.csv" --robot "$OUT/robot.toml" --meas-sigma 0.0003,0.001 \
    --systematic "$mode" --json "$OUT/fit_$mode.json" > "$OUT/report_$mode.txt" 2> "$OUT/time_$mode.txt"
  awk -v mode="$mode" -v json="$(tr -d '\n ' < "$OUT/fit_$mode.json")" '
    /Elapsed \(wall clock\)/ { n = split($NF, p, ":"); wall = (n == 3 ? p[1] * 3600 + p[2] * 60 + p[3] : p[1] * 60 + p[2]) }
    /User time/ { cpu += $NF } /System time/ { cpu += $NF }
    /Maximum resident set size/ { rss = $NF / 1024 }
    END {
      match(json, /"k_L":[-0-9.e+]+/); kl = substr(json, RSTART + 6, RLENGTH - 6)
      match(json, /"k_R":[-0-9.e+]+/); kr = substr(json, RSTART + 6, RLENGTH - 6)
      match(json, /"likelihood_passes":[0-9]+/); lp = substr(json, RSTART + 20, RLENGTH - 20)
      printf "| %s | %.1f | %.1f | %.0f | %.5g | %.5g | %s |\n", mode, wall, cpu, rss, kl, kr, lp
    }' "$OUT/time_$mode.txt"
done
echo "(truth: k_L = 0.0008, k_R = 0.0012 m^1/2; files in $OUT)"
