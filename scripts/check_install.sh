#!/usr/bin/env bash
# Installs the build in ${BUILD_DIR:-build} into a temporary prefix, builds
# the consumer project tests/consumer against it (CMake package) and runs
# it, compiles the same program with pkg-config's flags and runs that, and
# builds the .debs with CPack (umbmark, and python3-umbmark with the Python
# module), unpacks them and runs the binary and the module.
# Usage: check_install.sh   (after scripts/build.sh; exit 0 when both work)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$BUILD_DIR" --prefix "$tmp/prefix" >/dev/null
test -x "$tmp/prefix/bin/umbmark"
"$tmp/prefix/bin/umbmark" --version
launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S tests/consumer -B "$tmp/consumer" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$tmp/prefix" \
  "${launcher[@]}" >/dev/null
cmake --build "$tmp/consumer" >/dev/null
"$tmp/consumer/consumer" "$tmp/campaign-cmake"
libdir=$(dirname "$(find "$tmp/prefix" -name umbmark.pc -print -quit)")
PKG_CONFIG_PATH="$libdir" pkg-config --modversion umbmark
# shellcheck disable=SC2046
c++ -std=c++20 -O1 tests/consumer/main.cpp -o "$tmp/consumer-pc" $(PKG_CONFIG_PATH="$libdir" pkg-config --cflags --libs umbmark)
"$tmp/consumer-pc" "$tmp/campaign-pkgconfig"
# The Debian package: build it, unpack it (no root needed) and run the binary.
(cd "$BUILD_DIR" && cpack -G DEB -B "$tmp/deb" >/dev/null)
deb=$(find "$tmp/deb" -maxdepth 1 -name 'umbmark_*.deb' -print -quit)
dpkg-deb --info "$deb" | grep -E '^ (Package|Version|Depends):'
dpkg-deb -x "$deb" "$tmp/debroot"
"$tmp/debroot/usr/bin/umbmark" --version
# The Python module's package (when the build has the module): unpacked, it
# imports with Debian's python3 and calibrates the bundled example.
pydeb=$(find "$tmp/deb" -maxdepth 1 -name 'python3-umbmark_*.deb' -print -quit)
if ls "$BUILD_DIR"/umbmark.cpython-*.so >/dev/null 2>&1; then
  test -n "$pydeb" || { echo "check_install: no python3-umbmark .deb"; exit 1; }
  dpkg-deb --info "$pydeb" | grep -E '^ (Package|Version|Depends):'
  dpkg-deb -x "$pydeb" "$tmp/pyroot"
  # calibrate runs in the module's own process (the library is linked in):
  # no executable needed. The other functions run the umbmark binary of the
  # package umbmark (unpacked above).
  UMBMARK_EXE=/nonexistent/umbmark PYTHONPATH="$tmp/pyroot/usr/lib/python3/dist-packages" /usr/bin/python3 -c 'import sys, umbmark
assert umbmark.__file__.startswith(sys.argv[1]), umbmark.__file__
r = umbmark.calibrate("data/examples/endpoints.csv", robot="data/examples/robot.toml", side=0.75, no_heldout=True)
print("python3-umbmark", umbmark.__version__, "in-process calibrate: E_d =", r.E_d)' "$tmp/pyroot"
  UMBMARK_EXE="$tmp/debroot/usr/bin/umbmark" PYTHONPATH="$tmp/pyroot/usr/lib/python3/dist-packages" /usr/bin/python3 -c 'import umbmark
r = umbmark.evaluate("data/examples/square_ticks.csv", robot="data/examples/robot.toml")
print("python3-umbmark: evaluate through", umbmark.executable, "runs", r.summary["runs"])'
fi
echo "install: CMake package, pkg-config and .deb OK"
