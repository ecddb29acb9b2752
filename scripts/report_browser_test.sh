#!/usr/bin/env bash
# Renders every --report page in headless Chromium and checks it: the page
# loads from a file with the network off, the browser logs no console error,
# the rendered DOM holds the expected elements (headline, tables, inline SVG
# plots with ticks and legends), and a screenshot is taken (kept in OUTDIR
# for a person to look at). The fleet page (summarize) is also rendered for a
# generated fleet of 8 and of 5,000 robots (bench/fleet_gen.sh), and every
# page must fit a 1280 px window with no horizontal scroll (a copy of the
# page with a line of script that writes the document's scroll width into
# it is rendered by --dump-dom; the reports themselves carry no script).
# Usage: report_browser_test.sh UMBMARK_EXE SRC_DIR [OUTDIR]
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
for n in 8 5000; do
  rm -rf "$out/fleet$n"
  bash "$src/bench/fleet_gen.sh" "$n" "$out/fleet$n" >/dev/null
  "$exe" summarize "$out/fleet$n"/*.json --report "$out/fleet-$n.html" >/dev/null
done

fail=0
for page in calibrate evaluate fit-noise diagnose summarize fleet-8 fleet-5000; do
  html="$out/$page.html"
  profile=$(mktemp -d)
  flags=(--headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking
    --disable-component-update --disable-sync --user-data-dir="$profile" --enable-logging=stderr --v=0)
  timeout 120 "$browser" "${flags[@]}" --dump-dom "file://$html" >"$out/$page.dom" 2>"$out/$page.log" || true
  timeout 120 "$browser" "${flags[@]}" --screenshot="$out/$page.png" --window-size=1280,2400 "file://$html" \
    >/dev/null 2>>"$out/$page.log" || true
  # Width: the page's scroll width in a 1280 px window, from a copy with one line of script.
  sed 's|</body>|<script>document.body.insertAdjacentHTML("beforeend", "<pre id=\\"scroll-width\\">" + document.documentElement.scrollWidth + " " + window.innerWidth + "</pre>");</script></body>|' \
    "$html" >"$out/$page.width.html"
  timeout 120 "$browser" "${flags[@]}" --window-size=1280,900 --dump-dom "file://$out/$page.width.html" \
    >"$out/$page.width.dom" 2>>"$out/$page.log" || true
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
  read -r scroll_w window_w < <(sed -n 's|.*<pre id="scroll-width">\([0-9]*\) \([0-9]*\)</pre>.*|\1 \2|p' "$out/$page.width.dom") || true
  if [ -z "${scroll_w:-}" ]; then problems+=("scroll width not measured")
  elif [ "$scroll_w" -gt "$window_w" ]; then problems+=("horizontal scroll: ${scroll_w} px wide in a ${window_w} px window"); fi
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
    fleet-8 | fleet-5000)
      grep -q 'Outlier robots' "$out/$page.dom" || problems+=("no table of the outlier robots")
      grep -q 'R-00008' "$out/$page.dom" || problems+=("outlier R-00008 not named by its robot id")
      grep -q "$out/fleet" "$out/$page.dom" && problems+=("a robot named by its path")
      [ "$(grep -o 'data-title="' "$out/$page.dom" | wc -l)" -ge 7 ] || problems+=("not one distribution plot per quantity") ;;
  esac
  if [ ${#problems[@]} -gt 0 ]; then
    echo "FAIL $page: ${problems[*]}"
    fail=1
  else
    echo "ok   $page ($(wc -c <"$html") bytes, ${scroll_w} px wide in ${window_w}, screenshot $out/$page.png)"
  fi
done
exit $fail
