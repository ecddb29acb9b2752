#!/usr/bin/env bash
# Writes N calibrate JSON outputs of a generated fleet into OUTDIR (robot-00001.json ...),
# for the fleet summary's bench (bench/summarize_bench.sh) and its browser check
# (scripts/report_browser_test.sh). Usage: fleet_gen.sh N OUTDIR [SEED]
# The fleet: wheelbase 0.35 m and wheel diameters 0.15 m with 0.05 % production
# spread (normal), recorded with the nominal robot file; robot i (1-based) with
# i % 200 == 8 has a left wheel worn by 1.5 %, with i % 500 == 123 a wheelbase
# 3 % long (so 8 robots hold one planted outlier, 5,000 hold 35; at 5,000 the
# normal tails of the other quantities add about ten more beyond |z| 3.5). Each file carries a
# robot_id ("R-00001"), the keys summarize reads, and 20 runs and an evaluation
# like a real calibrate output, so the parse cost is near a real one's (2.5 kB each).
# Deterministic for a seed: the Park-Miller generator, exact in doubles, so
# the same under any awk.
set -euo pipefail
n=$1
out=$2
seed=${3:-31}
mkdir -p "$out"
awk -v n="$n" -v out="$out" -v seed="$seed" '
function rnd() { state = (state * 16807) % 2147483647; return state / 2147483647 }
function gauss(   u, v) { u = rnd(); v = rnd(); return sqrt(-2 * log(u)) * cos(6.283185307179586 * v) }
BEGIN {
  state = seed % 2147483646 + 1
  for (i = 1; i <= n; i++) {
    b = 0.35 * (1 + 5e-4 * gauss()); dl = 0.15 * (1 + 5e-4 * gauss()); dr = 0.15 * (1 + 5e-4 * gauss())
    if (i % 200 == 8) dl *= 0.985
    if (i % 500 == 123) b *= 1.03
    ed = dr / dl; eb = b / 0.35
    emax = 0.02 * (1 + 0.1 * gauss()); after = 0.004 * (1 + 0.2 * gauss())
    f = sprintf("%s/robot-%05d.json", out, i)
    printf "{\"input\":\"robot-%05d/campaign.toml\",\"robot_id\":\"R-%05d\",\"method\":\"umbmark\",", i, i > f
    printf "\"E_d\":%.12g,\"E_b\":%.12g,\"E_max_syst_m\":%.9g,", ed, eb, emax > f
    printf "\"parameters\":{\"wheelbase_m\":%.12g,\"wheel_diameter_left_m\":%.12g,\"wheel_diameter_right_m\":%.12g},", b, dl, dr > f
    printf "\"recorded_parameters\":{\"wheelbase_m\":0.35,\"wheel_diameter_left_m\":0.15,\"wheel_diameter_right_m\":0.15}," > f
    printf "\"runs\":[" > f
    for (k = 1; k <= 20; k++)
      printf "%s{\"run\":\"%d\",\"direction\":\"%s\",\"ex_m\":%.9g,\"ey_m\":%.9g,\"etheta_rad\":%.9g}", (k > 1 ? "," : ""), k,
             (k % 2 ? "cw" : "ccw"), 0.01 * gauss(), 0.01 * gauss(), 0.005 * gauss() > f
    printf "],\"evaluation\":{\"after\":{\"max_final_position_error_m\":%.9g,\"mean_final_position_error_m\":%.9g}}," , after, 0.6 * after > f
    printf "\"warnings\":[]}\n" > f
    close(f)
  }
}'
