#!/usr/bin/env bash
# The whole test suite: builds (Release, warnings as errors) and runs ctest.
# BUILD_DIR and extra CMake arguments as for build.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh "$@"
ctest --test-dir "${BUILD_DIR:-build}" --output-on-failure -j"$(nproc)" --timeout 900
