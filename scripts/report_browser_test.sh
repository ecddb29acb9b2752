#!/usr/bin/env bash
# Renders every --report page in headless Chromium and checks it: the page
# loads from a file with the network off, the browser logs no console error,
# the rendered DOM holds the expected elements (headline, tables, inline SVG
# plots with ticks and legends), and a screenshot is taken (kept in OUTDIR
# for a person to look at). Usage: report_browser_test.sh UMBMARK_EXE SRC_DIR [OUTDIR]
set -euo pipefail
exe=$1
src=$2
out=${3:-$(mktemp -d)}
mkdir -p "$out"
out=$(cd "$out" && pwd)   # file:// URLs need an absolute path
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then echo "report_browser_test: chromium not installed"; exit 77; fi
ex="$src/data/examples"

# One report per command, from the bundled examples.
"$exe" calibrate "$ex/calibrate.toml" --report "$out/calibrate.html" --json "$out/cal.json" >/dev/null
"$exe" evaluate "$ex/calibrate.toml" --params "$out/cal.json" --report "$out/evaluate.html" >/dev/null
"$exe" fit-noise "$ex/fit-noise.toml" --report "$out/fit-noise.html" >/dev/null
"$exe" diagnose "$ex/diagnose.toml" --null-sims 100 --report "$out/diagnose.html" >/dev/null
cp "$out/cal.json" "$out/cal2.json"
"$exe" summarize "$out/cal.json" "$out/cal2.json" "$out/cal.json" --report "$out/summarize.html" >/dev/null

fail=0
for page in calibrate evaluate fit-noise diagnose summarize; do
  html="$out/$page.html"
  profile=$(mktemp -d)
  flags=(--headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking
    --disable-component-update --disable-sync --user-data-dir="$profile" --enable-logging=stderr --v=0)
  timeout 120 "$browser" "${flags[@]}" --dump-dom "file://$html" >"$out/$page.dom" 2>"$out/$page.log" || true
  timeout 120 "$browser" "${flags[@]}" --screenshot="$out/$page.png" --window-size=1280,2400 "file://$html" \
    >/dev/null 2>>"$out/$page.log" || true
  rm -rf "$profile"
  problems=()
  grep -q 'class="headline' "$out/$page.dom" || problems+=("no headline")
  grep -q '<table class="numbers"' "$out/$page.dom" || problems+=("no table of numbers")
  grep -q '<figure class="plot"' "$out/$page.dom" || problems+=("no plot")
  grep -q 'class="tick x"' "$out/$page.dom" || problems+=("no axis ticks")
  grep -q 'class="legend-entry"' "$out/$page.dom" || problems+=("no legend")
  grep -qi '<script' "$html" && problems+=("has a script")
  grep -Eqi '(src|href)="https?:' "$html" && problems+=("refers to the network")
  # Console messages of the page (errors of the page itself, not the browser's own start-up noise).
  grep -E 'CONSOLE|Uncaught|Failed to load' "$out/$page.log" && problems+=("console errors")
  [ -s "$out/$page.png" ] || problems+=("no screenshot")
  # Page-specific elements: what each report must show.
  case $page in
    calibrate)
      grep -q 'Paths of all' "$out/$page.dom" || problems+=("not every run's path shown")
      grep -q 'class="worst-frame"' "$out/$page.dom" || problems+=("worst runs not marked") ;;
    evaluate)
      grep -q 'Position error along the path (all' "$out/$page.dom" || problems+=("not every run's error shown")
      grep -q 'Paths of the' "$out/$page.dom" || problems+=("no paths of the worst runs") ;;
    diagnose)
      grep -q 'data-title="Experiment 1' "$out/$page.dom" || problems+=("no residual panel per experiment")
      grep -q 'data-name="largest"' "$out/$page.dom" || problems+=("largest residuals not marked")
      grep -q 'class="series band"' "$out/$page.dom" || problems+=("no 95% band")
      grep -q 'What to do next' "$out/$page.dom" || problems+=("no next steps")
      grep -q ' mrad (se ' "$out/$page.dom" || problems+=("candidate parameters without units") ;;
  esac
  if [ ${#problems[@]} -gt 0 ]; then
    echo "FAIL $page: ${problems[*]}"
    fail=1
  else
    echo "ok   $page ($(wc -c <"$html") bytes, screenshot $out/$page.png)"
  fi
done
exit $fail
