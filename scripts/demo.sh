#!/usr/bin/env bash
# One command from a fresh Debian machine: installs the packages, builds, and
# runs `umbmark calibrate` on the bundled example data (real OptiOdom square
# runs, imported into the contract's formats first).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
bash scripts/python_path.sh  # `import umbmark` from the build tree (docs/python.md)
OUT=${BUILD_DIR:-build}/example
UMB=${BUILD_DIR:-build}/umbmark
echo "== umbmark import optiodom (real square runs, OptiOdom June 2020, MIT)"
"$UMB" import optiodom data/optiodom-2020-06/square/230620202042 --out "$OUT/square-230620202042"
echo
echo "== umbmark calibrate on the trajectory runs (manifest)"
"$UMB" calibrate "$OUT/square-230620202042/campaign.toml" --plot "$OUT/calibration.svg" \
  --ros2 "$OUT/diff_drive_calibration.yaml" --json "$OUT/calibration.json"
echo
echo "== umbmark calibrate on endpoint return errors (tape-measure style CSV)"
"$UMB" calibrate data/examples/endpoints.csv --robot data/examples/robot.toml --side 0.75
echo
echo "== umbmark evaluate the calibration on the same runs"
"$UMB" evaluate "$OUT/square-230620202042/campaign.toml" --params "$OUT/calibration.json" | tail -4
echo
echo "Wrote $OUT/calibration.json, $OUT/calibration.svg, $OUT/diff_drive_calibration.yaml"
