#!/usr/bin/env bash
# Configures and builds umbmark (Release, warnings as errors) into ${BUILD_DIR:-build}.
# Extra CMake arguments are passed through, e.g. -DUMBMARK_SANITIZE=ON.
# Uses ccache and the mold linker when they are installed (faster rebuilds);
# neither is required.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
extra=()
if command -v ccache >/dev/null 2>&1; then extra+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
if command -v mold >/dev/null 2>&1; then extra+=(-DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=mold); fi
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=${BUILD_TYPE:-Release} -DUMBMARK_WERROR=ON "${extra[@]}" "$@" >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)"
