#!/usr/bin/env bash
# Configures and builds umbmark (Release, warnings as errors) into ${BUILD_DIR:-build}.
# Extra CMake arguments are passed through, e.g. -DUMBMARK_SANITIZE=ON.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=${BUILD_TYPE:-Release} -DUMBMARK_WERROR=ON "$@" >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)"
