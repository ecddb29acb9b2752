#!/usr/bin/env bash
# Real-data diagnosis: the June 2020 OptiOdom sessions in one campaign
# (squares as `square` experiments, circular and Ivanjko runs as `free`
# experiments), and per path type, as written up in docs/diagnosis.md.
#
# Every dataset is imported with `umbmark import optiodom`; one manifest
# lists them all against the reference robot 0.2 m / 84 mm / 2796.8 ticks
# per wheel revolution. Ticks are physical, so runs recorded while the
# odometry used other parameters (0.205 m, 85 mm) convert the same way; the
# free and trajectory experiments are replayed from their ticks, so no
# commanded motion is assumed.
#
# Usage: bench/optiodom_diagnose.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail

BUILD=${1:-build}
OUT=${2:-$(mktemp -d "${TMPDIR:-/tmp}/umbmark-optiodom.XXXXXX")}
HERE=$(cd "$(dirname "$0")/.." && pwd)
DATA="$HERE/data/optiodom-2020-06"
UMBMARK="$BUILD/umbmark"
[[ -x "$UMBMARK" ]] || { echo "missing $UMBMARK" >&2; exit 2; }
mkdir -p "$OUT"

for dir in "$DATA"/square/* "$DATA"/circular/* "$DATA"/ivanjko/*; do
  [[ -d "$dir" ]] || continue
  name="$(basename "$(dirname "$dir")")_$(basename "$dir")"
  "$UMBMARK" import optiodom "$dir" --out "$OUT/$name" > /dev/null
done

manifest() {  # manifest FILE PATTERN...
  local file=$1; shift
  {
    printf '# June 2020 OptiOdom sessions, reference robot of the runs recorded with nominal parameters\n'
    printf '[robot]\nwheelbase_m = 0.2\nwheel_diameter_left_m = 0.084\nwheel_diameter_right_m = 0.084\nticks_per_rev = 2796.8\n'
    for pattern in "$@"; do
      for d in "$OUT"/$pattern; do
        [[ -d "$d" ]] || continue
        local n; n=$(basename "$d")
        if [[ $n == square_* ]]; then
          printf '\n[[experiment]]\nkind = "square"\nside_m = 0.75\nfile = "%s/runs.csv"\n' "$n"
        else
          printf '\n[[experiment]]\nkind = "free"\nfile = "%s/runs.csv"\n' "$n"
        fi
      done
    done
  } > "$file"
}

manifest "$OUT/june_all.toml" 'square_*' 'circular_*' 'ivanjko_*'
manifest "$OUT/june_squares.toml" 'square_*'
manifest "$OUT/june_circles.toml" 'circular_*'
manifest "$OUT/june_ivanjko.toml" 'ivanjko_*'

for m in june_all june_squares june_circles june_ivanjko; do
  "$UMBMARK" diagnose "$OUT/$m.toml" --json "$OUT/$m.json" --plot "$OUT/$m.svg" > "$OUT/$m.txt"
  echo "== $m: $(grep -A1 '^4. Verdict' "$OUT/$m.txt" | tail -1 | sed 's/^ *//')"
done
echo "reports in $OUT"
