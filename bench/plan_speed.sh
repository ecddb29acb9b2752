#!/usr/bin/env bash
# Speed and peak memory of `umbmark plan` and `umbmark plan --check`
# (issue 30 targets: plan < 1 s, plan --check < 2 s on a standard campaign).
# Timing lives here, never in a unit test.
#   - plan: the Monte Carlo bench's robot and targets (bench/plan_montecarlo.sh:
#     E_d 4e-4, E_b 1.5e-3, k 1.5e-4, 2 m of floor);
#   - plan --check on two campaigns of the independent generator
#     (bench/indep_campaign.cpp, its default 20 Hz logging): "standard" = Borenstein & Feng's
#     5 cw + 5 ccw squares of 2 m with 10 back-and-forth runs of 2 m; and
#     "planned" = the design plan returns above (its squares and
#     back-and-forth runs), wheel noise fitted by --check itself (the slower
#     path: fit-noise inside).
# Each command REPEAT times (default 5): median and worst wall time, peak
# resident memory (GNU time's maximum RSS), on whatever else the machine runs.
# Usage: bench/plan_speed.sh [BUILD_DIR [REPEAT [SEED]]]
set -euo pipefail
BUILD=${1:-build}
REPEAT=${2:-5}
SEED=${3:-4242}
UMBMARK="$BUILD/umbmark"
GEN="$BUILD/indep_campaign"
for exe in "$UMBMARK" "$GEN"; do
  [[ -x "$exe" ]] || { echo "missing $exe (build the umbmark and indep_campaign targets)" >&2; exit 2; }
done
[[ -x /usr/bin/time ]] || { echo "this bench needs GNU time (/usr/bin/time)" >&2; exit 2; }
command -v jq >/dev/null || { echo "this bench needs jq" >&2; exit 2; }
OUT=$(mktemp -d "${TMPDIR:-/tmp}/umbmark-plan-speed.XXXXXX")
trap 'rm -rf "$OUT"' EXIT
B=0.4 D=0.1 KL=1.2e-3 KR=0.8e-3 ED=1.004 EB=0.985
cat > "$OUT/robot.toml" <<EOF
wheelbase_m = $B
wheel_diameter_left_m = $D
wheel_diameter_right_m = $D
ticks_per_rev = 4096
EOF

# measure LABEL CMD...: REPEAT runs; prints median / worst wall [s] and peak RSS [MiB].
measure() {
  local label=$1
  shift
  : > "$OUT/t.txt"
  for _ in $(seq 1 "$REPEAT"); do
    /usr/bin/time -f "%e %M" -o "$OUT/one.txt" "$@" > /dev/null 2> "$OUT/err.txt" ||
      { echo "$label failed:" >&2; cat "$OUT/err.txt" >&2; exit 1; }
    cat "$OUT/one.txt" >> "$OUT/t.txt"
  done
  sort -n "$OUT/t.txt" | awk -v label="$label" '
    { t[NR] = $1; if ($2 > m) m = $2 }
    END { printf "| %s | %.2f | %.2f | %.1f |\n", label, t[int((NR + 1) / 2)], t[NR], m / 1024 }'
}

echo "| command | median wall [s] | worst wall [s] | peak RSS [MiB] |"
echo "|---|---|---|---|"
PLAN=("$UMBMARK" plan --robot "$OUT/robot.toml" --kl $KL --kr $KR --target-E_d 4e-4 --target-E_b 1.5e-3
  --target-k 1.5e-4 --max-side 2 --json "$OUT/plan.json")
measure "plan (E_d, E_b, k targets, 2 m floor)" "${PLAN[@]}"
side=$(jq -r .design.square_side_m "$OUT/plan.json")
runs=$(jq -r .design.runs_cw "$OUT/plan.json")
bf=$(jq -r .design.back_and_forth_runs "$OUT/plan.json")
len=$(jq -r .design.back_and_forth_length_m "$OUT/plan.json")
[[ "$len" == 0 ]] && len=1

"$GEN" --out "$OUT/standard" --seed "$SEED" --side 2 --square-runs 5 --fwd-back-runs 10 --distance 2 \
  --kl $KL --kr $KR --E-d $ED --E-b $EB --wheelbase $B --diameter $D > /dev/null
"$GEN" --out "$OUT/planned" --seed "$((SEED + 1))" --side "$side" --square-runs "$runs" --fwd-back-runs "$bf" \
  --distance "$len" --kl $KL --kr $KR --E-d $ED --E-b $EB --wheelbase $B --diameter $D > /dev/null
samples() { awk -F, 'FNR > 1 { n++ } END { print n }' "$1"/*.csv; }
measure "plan --check, standard: 5 + 5 squares of 2 m, 10 back-and-forth ($(samples "$OUT/standard") samples)" \
  "$UMBMARK" plan --check "$OUT/standard/campaign.toml"
measure "plan --check, standard, --kl/--kr given" \
  "$UMBMARK" plan --check "$OUT/standard/campaign.toml" --kl $KL --kr $KR
measure "plan --check, the planned design: $runs + $runs squares of $side m, $bf back-and-forth of $len m ($(samples "$OUT/planned") samples)" \
  "$UMBMARK" plan --check "$OUT/planned/campaign.toml"
echo "targets: plan < 1 s, plan --check < 2 s (repeat $REPEAT, seed $SEED)"
