#!/usr/bin/env bash
# Makes `import umbmark` work from the build tree (docs/python.md): writes
# umbmark.pth (one line: the build folder) into the site-packages of the
# python3 first on PATH and of Debian's /usr/bin/python3 (the user site when
# the interpreter has one, else its first site-packages folder), then checks
# the import. An interpreter of another Python minor version than the module
# was built for is reported, not changed.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=$(cd "${BUILD_DIR:-build}" && pwd)
if ! ls "$BUILD"/umbmark.cpython-*.so >/dev/null 2>&1; then
  echo "python_path.sh: no Python module in $BUILD (pybind11 not installed?); skipped" >&2
  exit 0
fi
declare -A done_dirs=()
for py in "$(command -v python3 || true)" /usr/bin/python3; do
  [ -n "$py" ] && [ -x "$py" ] || continue
  dir=$("$py" -c 'import site, sys
print(site.getusersitepackages() if site.ENABLE_USER_SITE else site.getsitepackages()[0])')
  if [ -z "${done_dirs[$dir]:-}" ]; then
    mkdir -p "$dir"
    echo "$BUILD" >"$dir/umbmark.pth"
    done_dirs[$dir]=1
  fi
  if "$py" -c 'import umbmark' 2>/dev/null; then
    echo "import umbmark works for $py ($("$py" -c 'import sys; print(sys.version.split()[0])'); $dir/umbmark.pth)"
  else
    echo "python_path.sh: $py cannot import the module built in $BUILD (another Python version?); use /usr/bin/python3" >&2
  fi
done
