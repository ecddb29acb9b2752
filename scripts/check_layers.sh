#!/usr/bin/env bash
# Include-direction check: fails when a file of lib/ or apps/ includes a
# header from a higher layer (or from a peer folder of the same layer). The
# layers, lowest first (docs/architecture.md):
#
#   0   core                          data types, angles, poses, errors
#   1   stats, kinematics, scan       numerics; wheel travel -> pose; scan registration
#   2   model                         the true robot and its controller
#   2.5 effects                       one file per unmodelled effect (simulation and diagnosis use them)
#   3   error_models, evaluation      noise propagation; return errors
#   3.1 output, report                the file rooms: atomic writes, output sets, locks;
#                                     SVG plots and HTML pages
#   3.2 formats                       CSV, TOML, manifest, params JSON, ROS 2 YAML, campaigns
#   3.3 ros2                          bag containers, CDR, messages, /tf (reading only)
#   3.4 ground_truth                  ground-truth sources read from a recording
#   3.5 import                        the importers (rosbag2, OptiOdom) and their checks
#   4   calibration, simulation       UMBmark + refine; simulators
#   4.5 planning                      which runs to drive; what a campaign determines
#                                     (diagnose uses its analysis)
#   5   diagnosis                     sim-to-real gap
#   5.5 api                           one call per command (options -> result -> JSON)
#   6   apps                          the command-line suite
#
# (ranks below are tenths: 3.2 is 32). A folder may include its own headers
# and those of any lower layer. Only the file rooms themselves, apps and
# diagnosis may include a file room (the computing layers never touch files;
# diagnosis still reads its campaign itself). A folder of lib/ not in the
# table is an error: add it here and to docs/architecture.md.
# Usage: check_layers.sh [repo root]   (exit 0 clean, 1 on a violation)
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
declare -A rank=([core]=0 [stats]=10 [kinematics]=10 [scan]=10 [model]=20 [effects]=25 [error_models]=30 [evaluation]=30
  [output]=31 [report]=31 [formats]=32 [ros2]=33 [ground_truth]=34 [import]=35
  [calibration]=40 [simulation]=40 [diagnosis]=50 [planning]=45 [api]=55 [apps]=60)
declare -A file_room=([output]=1 [report]=1 [formats]=1 [ros2]=1 [ground_truth]=1 [import]=1)
declare -A file_room_users=([diagnosis]=1 [api]=1 [apps]=1)
# "3.2" for rank 32.
layer() { local r=${rank[$1]}; if ((r % 10)); then echo "$((r / 10)).$((r % 10))"; else echo "$((r / 10))"; fi; }
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
      echo "$file:$line: includes \"$header\": layer $to ($(layer "$to")) is not below $from ($(layer "$from"))"
      status=1
    elif [[ -n ${file_room[$to]+x} && -z ${file_room[$from]+x} && -z ${file_room_users[$from]+x} ]]; then
      echo "$file:$line: includes \"$header\": only the file rooms, apps and diagnosis may use $to"
      status=1
    fi
  done < <(grep -n '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$file" || true)
done < <(find lib apps -type f \( -name '*.hpp' -o -name '*.cpp' -o -name '*.h' \) -print0 | sort -z)
if ((status == 0)); then echo "layering: every include goes down a layer"; fi
exit $status
