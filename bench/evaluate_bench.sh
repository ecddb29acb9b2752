#!/usr/bin/env bash
# Whole-process `umbmark evaluate` on a large trajectory log against
# pandas.read_csv of the same file, in the same run (issue 13, part 4).
# Generates a recorder-like trajectory CSV (default 200 runs x 20000 rows =
# 4 M rows, ~262 MB) with bench_parse, warms the page cache, then times
# (best of REPEATS, interleaved so both see the same machine load):
#   - umbmark evaluate FILE --robot R.toml   (read + parse + odometry + errors)
#   - pandas.read_csv(FILE)                  (parse only, inside Python, import excluded)
# and prints MB/s of both, their ratio (wall clock and CPU time), and the
# peak memory of each process (/usr/bin/time -v). Targets (issue 23): ratio
# >= 3 (wall clock), umbmark peak memory <= 128 MB. evaluate reads the next
# run on a second thread while it evaluates the one before (formats/run_prefetch),
# so on one core the wall ratio falls back to about the CPU-time ratio.
# The file is deleted at the end.
#   usage: bench/evaluate_bench.sh [BUILD_DIR]      (default: build)
#   env:   EVAL_BENCH_RUNS (200), EVAL_BENCH_ROWS (20000), EVAL_BENCH_REPEATS (3),
#          EVAL_BENCH_DIR (default: $TMPDIR/umbmark_eval_bench), PYTHON (python3 with pandas)
set -euo pipefail

build_dir=${1:-build}
umbmark=$build_dir/umbmark
bench=$build_dir/bench_parse
runs=${EVAL_BENCH_RUNS:-200}
rows=${EVAL_BENCH_ROWS:-20000}
repeats=${EVAL_BENCH_REPEATS:-3}
dir=${EVAL_BENCH_DIR:-${TMPDIR:-/tmp}/umbmark_eval_bench}
python=${PYTHON:-}
if [[ -z $python ]]; then
  for p in python3 /usr/bin/python3; do
    if "$p" -c "import pandas" 2>/dev/null; then python=$p; break; fi
  done
fi
if [[ -z $python ]]; then
  echo "evaluate_bench.sh: no python3 with pandas (apt-get install python3-pandas)" >&2
  exit 2
fi
for exe in "$umbmark" "$bench"; do
  if [[ ! -x $exe ]]; then
    echo "evaluate_bench.sh: $exe not found; build it first: cmake --build $build_dir --target umbmark bench_parse" >&2
    exit 2
  fi
done
if [[ ! -x /usr/bin/time ]]; then
  echo "evaluate_bench.sh: /usr/bin/time (GNU time) is needed for peak memory" >&2
  exit 2
fi

mkdir -p "$dir"
file=$dir/trajectory_${runs}x${rows}.csv
robot=$dir/robot.toml
trap 'rm -f "$file" "$robot" "$dir"/time.* "$dir"/pandas.out; rmdir "$dir" 2>/dev/null || true' EXIT
# The generator's robot: 0.34 m wheelbase, 0.1524 m wheels, 2048 ticks/rev.
printf 'wheelbase_m = 0.34\nwheel_diameter_left_m = 0.1524\nwheel_diameter_right_m = 0.1524\nticks_per_rev = 2048\n' \
  > "$robot"
"$bench" --generate-runs "$file" "$runs" "$rows"
cat "$file" > /dev/null  # warm the page cache so both read from memory
bytes=$(stat -c %s "$file")

# field NAME FILE: a value from /usr/bin/time -v output.
field() { sed -n "s/^[[:space:]]*$1:[[:space:]]*//p" "$2"; }
secs() {  # m:ss.ss or h:mm:ss -> seconds
  awk -F: '{ s = 0; for (i = 1; i <= NF; i++) s = s * 60 + $i; print s }' <<< "$1"
}
min() { awk -v a="$1" -v b="$2" 'BEGIN { print (b == "" || a < b) ? a : b }'; }
max() { awk -v a="$1" -v b="$2" 'BEGIN { print (b == "" || a > b) ? a : b }'; }

best_u_wall="" best_u_cpu="" peak_u="" best_p_wall="" best_p_cpu="" peak_p=""
for ((k = 1; k <= repeats; k++)); do
  /usr/bin/time -v -o "$dir/time.u" "$umbmark" evaluate "$file" --robot "$robot" > /dev/null
  wall=$(secs "$(field 'Elapsed (wall clock) time (h:mm:ss or m:ss)' "$dir/time.u")")
  cpu=$(awk -v u="$(field 'User time (seconds)' "$dir/time.u")" -v s="$(field 'System time (seconds)' "$dir/time.u")" \
    'BEGIN { print u + s }')
  best_u_wall=$(min "$wall" "$best_u_wall")
  best_u_cpu=$(min "$cpu" "$best_u_cpu")
  peak_u=$(max "$(field 'Maximum resident set size (kbytes)' "$dir/time.u")" "$peak_u")

  # pandas: read_csv timed inside Python (wall and process CPU time), so
  # the interpreter's start-up and `import pandas` do not count against it.
  /usr/bin/time -v -o "$dir/time.p" "$python" -c '
import sys, time, pandas
w, c = time.perf_counter(), time.process_time()
df = pandas.read_csv(sys.argv[1], comment="#")
print(time.perf_counter() - w, time.process_time() - c, len(df))' "$file" > "$dir/pandas.out"
  read -r p_wall p_cpu p_rows < "$dir/pandas.out"
  best_p_wall=$(min "$p_wall" "$best_p_wall")
  best_p_cpu=$(min "$p_cpu" "$best_p_cpu")
  peak_p=$(max "$(field 'Maximum resident set size (kbytes)' "$dir/time.p")" "$peak_p")
done

mbps() { awk -v b="$bytes" -v s="$1" 'BEGIN { if (s > 0) printf "%.1f", b / 1e6 / s; else print "inf" }'; }
# Largest run in memory: 7 arrays of 8 bytes per sample (t, two counts,
# three ground-truth values, line number).
largest_run_mb=$(awk -v r="$rows" 'BEGIN { printf "%.1f", r * 7 * 8 / 1e6 }')
echo "file:    $file ($(awk -v b="$bytes" 'BEGIN { printf "%.1f", b / 1e6 }') MB, $runs runs x $rows rows = $p_rows rows)"
echo "umbmark evaluate (whole process): $(mbps "$best_u_wall") MB/s wall, $(mbps "$best_u_cpu") MB/s CPU time (best of $repeats)"
echo "pandas.read_csv (parse only):     $(mbps "$best_p_wall") MB/s wall, $(mbps "$best_p_cpu") MB/s CPU time (best of $repeats)"
awk -v uw="$best_u_wall" -v pw="$best_p_wall" -v uc="$best_u_cpu" -v pc="$best_p_cpu" \
  'BEGIN { printf "ratio umbmark / pandas: %.2fx (wall), %.2fx (CPU time)   target >= 3x\n", pw / uw, pc / uc }'
awk -v u="$peak_u" -v p="$peak_p" -v r="$largest_run_mb" \
  'BEGIN { printf "peak memory: umbmark %.1f MB, pandas process %.1f MB   target: umbmark <= 128 MB (largest run %.1f MB)\n", u / 1024, p / 1024, r }'
