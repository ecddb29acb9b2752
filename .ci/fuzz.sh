#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/*.cpp) with clang++ and runs each for
# FUZZ_SECONDS (default 60), seeded from the test data (tests/data/good,
# tests/data/bad, the shipped example data; small MCAP files and CDR messages
# of tests/data/rosbag2 for fuzz_mcap and fuzz_cdr). Fails on any crash, sanitizer
# report, timeout or out-of-memory; the reproducer is left in
# $FUZZ_BUILD_DIR/artifacts/.
# Budget with the defaults: 4 targets x 60 s + 3 x 30 s (fuzz_params_json,
# fuzz_manifest, fuzz_endpoint_csv) = 5.5 min of fuzzing, run FUZZ_PARALLEL
# at a time (default nproc: about 3 min on 2 cores), plus the build.
#   env: FUZZ_SECONDS (60), FUZZ_PARALLEL (nproc), FUZZ_NEW_SECONDS (30: the three newer targets), FUZZ_BUILD_DIR (build-fuzz), FUZZ_CXX (clang++)
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${FUZZ_SECONDS:-60}
build=${FUZZ_BUILD_DIR:-build-fuzz}
cxx=${FUZZ_CXX:-clang++}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

CXX=$cxx cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DUMBMARK_BUILD_FUZZ=ON -DUMBMARK_BUILD_TESTS=OFF -DUMBMARK_BUILD_BENCH=OFF
targets=()
for src in fuzz/*.cpp; do targets+=("$(basename "$src" .cpp)"); done
cmake --build "$build" --target "${targets[@]}" -j"${FUZZ_JOBS:-2}"

# Dictionaries: the tokens a mutator would take long to find by itself.
cat > "$build/csv.dict" <<'DICT'
"run"
"direction"
"t_s"
"ticks_left"
"ticks_right"
"dist_left_m"
"dist_right_m"
"x_gt_m"
"y_gt_m"
"theta_gt_rad"
"ex_m"
"ey_m"
"etheta_rad"
"x_abs_m"
"theta_odo_rad"
"_mm"
"_deg"
","
",,,"
"\x0d\x0a"
"\x0a"
"#"
"\""
",\""
"\"\""
"\"\x0a"
"\xef\xbb\xbf"
"nan"
"inf"
"e308"
"-9223372036854775808"
"1073741824"
"\""
DICT
cat > "$build/toml.dict" <<'DICT'
"wheelbase_m"
"wheel_diameter_left_m"
"wheel_diameter_right_m"
"ticks_per_rev"
"[robot]"
"[[experiment]]"
"[ground_truth]"
"kind"
"\"square\""
"\"back_and_forth\""
"\"free\""
"side_m"
"distance_m"
"file"
"sigma_xy_m"
"sigma_theta_rad"
" = "
"nan"
"inf"
DICT

cat > "$build/json.dict" <<'DICT'
"parameters"
"refined"
"results"
"wheelbase_m"
"wheel_diameter_left_m"
"wheel_diameter_right_m"
"ticks_per_rev"
"1e400"
"-0"
"null"
"\\u0000"
"\xff"
DICT

# One target's seeds, dictionary and run; its log goes to $build/logs/TARGET.log
# and its exit status to $build/logs/TARGET.status.
fuzz_one() {
  local target=$1 seeds="$build/seeds/$1" corpus="$build/corpus/$1" dict=""
  mkdir -p "$seeds" "$corpus" "$build/artifacts"
  case $target in
    fuzz_csv)
      dict=csv.dict
      find tests/data data -maxdepth 3 -type f \( -name '*.csv' -o -name '*.bin' \) -size -64k \
        -exec cp {} "$seeds/" \; ;;
    fuzz_toml)
      dict=toml.dict
      find tests/data data -maxdepth 3 -type f -name '*.toml' -exec cp {} "$seeds/" \; ;;
    fuzz_mcap)
      find tests/data/rosbag2 -type f -name '*.mcap' -size -64k -exec cp {} "$seeds/" \; ;;
    fuzz_cdr)
      cp tests/data/rosbag2/cdr/*.bin "$seeds/" ;;
    fuzz_manifest)
      dict=toml.dict
      find tests/data data -maxdepth 3 -type f -name '*.toml' -exec cp {} "$seeds/" \; ;;
    fuzz_endpoint_csv)
      dict=csv.dict
      find tests/data data -maxdepth 3 -type f -name '*.csv' -size -64k -exec grep -l -e 'ex_m' -e 'ex_mm' -e 'x_abs' {} + \
        | xargs -r cp -t "$seeds/" ;;
    fuzz_params_json)
      dict=json.dict
      cat > "$seeds/cal.json" <<'JSON'
{"E_d": 1.0, "parameters": {"wheelbase_m": 0.34, "wheel_diameter_left_m": 0.1524, "wheel_diameter_right_m": 0.1525, "ticks_per_rev": 2048}, "warnings": []}
JSON
      cat > "$seeds/refined.json" <<'JSON'
{"results": [{"parameters": {"wheelbase_m": 0.34, "wheel_diameter_left_m": 0.15, "wheel_diameter_right_m": 0.15},
 "refined": {"parameters": {"wheelbase_m": 0.341, "wheel_diameter_left_m": 0.1523, "wheel_diameter_right_m": 0.1526}}}]}
JSON
      ;;
  esac
  # Targets added by issue 9 run FUZZ_NEW_SECONDS (default 30) to keep CI short.
  local t_seconds=$seconds
  case $target in fuzz_params_json | fuzz_manifest | fuzz_endpoint_csv) t_seconds=${FUZZ_NEW_SECONDS:-30} ;; esac
  echo "== $target: $(ls "$seeds" | wc -l) seed files, $(ls "$corpus" | wc -l) corpus files, ${t_seconds} s"
  local args=(-max_total_time="$t_seconds" -timeout=10 -rss_limit_mb=2048 -max_len=16384 -print_final_stats=1
              -artifact_prefix="$build/artifacts/$target-")
  if [[ -n $dict ]]; then args+=(-dict="$build/$dict"); fi
  "$build/$target" "${args[@]}" "$corpus" "$seeds"
}

# The targets run FUZZ_PARALLEL at a time (default: the number of cores), each
# for its full time: the same fuzzing in less wall time. Each log is printed
# whole, in order, when all are done (short: progress lines and libFuzzer's
# dictionary advice are filtered out).
mkdir -p "$build/logs"
parallel=${FUZZ_PARALLEL:-$(nproc)}
running=0
for target in "${targets[@]}"; do
  if (( running >= parallel )); then wait -n || true; running=$((running - 1)); fi
  ( set +e; fuzz_one "$target" > "$build/logs/$target.log" 2>&1; echo $? > "$build/logs/$target.status" ) &
  running=$((running + 1))
done
wait

status=0
for target in "${targets[@]}"; do
  grep -v -e '# Uses:' -e 'NEW_FUNC' -e '^#[0-9]*[[:space:]]*\(NEW\|REDUCE\|pulse\|RELOAD\)' "$build/logs/$target.log" | tail -n 40
  if [[ "$(cat "$build/logs/$target.status" 2>/dev/null)" != 0 ]]; then
    echo "FUZZ FAILURE in $target (exit $(cat "$build/logs/$target.status" 2>/dev/null)); reproducers:" >&2
    ls -l "$build/artifacts" >&2 || true
    status=1
  fi
done
exit $status
