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
# ROBOT=B generates the same set for robot B (the second design) on seeds
# 9301-9316. SEED_BASE=N generates the same sixteen cases on seeds N+1 ..
# N+16 instead (a fresh set: robot A 9401-9416 and robot B 9501-9516 were
# generated in session 15, after the rules they measure were frozen).
#
# Usage: bench/dart_scatter_set.sh [BUILD_DIR] [KEEP_DIR] [JOBS]
#   (about 10-15 minutes on 2 cores; KEEP_DIR keeps the campaigns, and a
#   second call with the same KEEP_DIR only diagnoses them again)
set -euo pipefail
BUILD=${1:-build}
KEEP=${2:-$(mktemp -d "${TMPDIR:-/tmp}/umbmark-dart-scatter.XXXXXX")}
JOBS=${3:-2}
HERE=$(cd "$(dirname "$0")" && pwd)
# robot A: seeds 9201-9216; ROBOT=B (the second design): seeds 9301-9316
base=${SEED_BASE:-$([[ "${ROBOT:-A}" == B ]] && echo 9300 || echo 9200)}
CASES=""
i=0
for cls in clean clean stop_slide swivel_castor floor_strips turn_scrub marker_offset clock_fixed clock_per_run \
  eccentric_hubs marker_offset+stop_slide clock_fixed+turn_scrub swivel_castor+marker_offset \
  floor_strips+clock_per_run stop_slide+clock_fixed turn_scrub+marker_offset; do
  i=$((i + 1))
  CASES+="$cls:$((base + i)) "
done
CASES="$CASES" SCATTER=1 KEEP="$KEEP" ROBOT="${ROBOT:-A}" bash "$HERE/dart_validation.sh" "$BUILD" 1 "$((base + 1))" "$JOBS"
