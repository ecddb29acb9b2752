#!/usr/bin/env bash
# Include-direction check: fails when a file of lib/ or apps/ includes a
# header from a higher layer (or from a peer folder of the same layer). The
# layers, lowest first (docs/architecture.md):
#
#   0 core                          data types, angles, poses, errors
#   1 stats, kinematics, scan       numerics; wheel travel -> pose; scan registration
#   2 model                         the true robot and its controller
#   3 io, error_models, evaluation  files; noise propagation; return errors
#   4 calibration, simulation       UMBmark + refine; simulators
#   5 diagnosis                     sim-to-real gap
#   6 apps                          the command-line suite
#
# A folder may include its own headers and those of any lower layer. Only
# apps and diagnosis may include io (the computing layers never touch files;
# diagnosis still reads its campaign itself). A folder of lib/ not in the
# table is an error: add it here and to docs/architecture.md.
# Usage: check_layers.sh [repo root]   (exit 0 clean, 1 on a violation)
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
declare -A rank=([core]=0 [stats]=1 [kinematics]=1 [scan]=1 [model]=2 [io]=3 [error_models]=3 [evaluation]=3
  [calibration]=4 [simulation]=4 [diagnosis]=5 [apps]=6)
declare -A io_allowed=([io]=1 [diagnosis]=1 [apps]=1)
status=0
cd "$root"
while IFS= read -r -d '' file; do
  if [[ $file == apps/* ]]; then from=apps; else from=${file#lib/}; from=${from%%/*}; fi
  if [[ -z ${rank[$from]+x} ]]; then
    echo "$file: folder '$from' has no layer (add it to scripts/check_layers.sh)"
    status=1
    continue
  fi
  while IFS= read -r hit; do
    line=${hit%%:*}
    header=${hit#*\"}
    header=${header%%\"*}
    [[ $header == */* ]] || continue  # same-folder include ("common.hpp")
    to=${header%%/*}
    [[ -n ${rank[$to]+x} ]] || continue  # not one of ours (e.g. <ceres/...> spelled with quotes)
    [[ $to == "$from" ]] && continue
    if ((rank[$to] >= rank[$from])); then
      echo "$file:$line: includes \"$header\": layer $to (${rank[$to]}) is not below $from (${rank[$from]})"
      status=1
    elif [[ $to == io && -z ${io_allowed[$from]+x} ]]; then
      echo "$file:$line: includes \"$header\": only apps and diagnosis may use io"
      status=1
    fi
  done < <(grep -n '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$file" || true)
done < <(find lib apps -type f \( -name '*.hpp' -o -name '*.cpp' -o -name '*.h' \) -print0 | sort -z)
if ((status == 0)); then echo "layering: every include goes down a layer"; fi
exit $status
