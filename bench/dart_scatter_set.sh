#!/usr/bin/env bash
# The DART set with a real robot's scatter (issue 28, item 7; table in
# docs/diagnosis.md, "Physics with a real robot's scatter"): robot A with
# wheel-ground contact noise (k = 0.0002 m^1/2: about 2 mm of run-to-run
# return scatter), a random start pose and castor angle per run, 2 clean
# robots, 8 single causes and 6 campaigns with two causes at once, on fresh
# seeds (9201-9216, never generated before this set was frozen). The
# expected verdict of each campaign is decided from the causes measured in
# the engine (truth.md), not from its class label.
#
# Usage: bench/dart_scatter_set.sh [BUILD_DIR] [KEEP_DIR] [JOBS]
#   (about 10-15 minutes on 2 cores; KEEP_DIR keeps the campaigns, and a
#   second call with the same KEEP_DIR only diagnoses them again)
set -euo pipefail
BUILD=${1:-build}
KEEP=${2:-$(mktemp -d "${TMPDIR:-/tmp}/umbmark-dart-scatter.XXXXXX")}
JOBS=${3:-2}
HERE=$(cd "$(dirname "$0")" && pwd)
CASES="clean:9201 clean:9202
stop_slide:9203 swivel_castor:9204 floor_strips:9205 turn_scrub:9206
marker_offset:9207 clock_fixed:9208 clock_per_run:9209 eccentric_hubs:9210
marker_offset+stop_slide:9211 clock_fixed+turn_scrub:9212 swivel_castor+marker_offset:9213
floor_strips+clock_per_run:9214 stop_slide+clock_fixed:9215 turn_scrub+marker_offset:9216"
CASES=$(echo $CASES) SCATTER=1 KEEP="$KEEP" bash "$HERE/dart_validation.sh" "$BUILD" 1 9201 "$JOBS"
