#!/usr/bin/env bash
# Monte Carlo of castor_swivel's first-start extension (docs/diagnosis.md,
# "A swivel castor's first start"): `umbmark simulate` with a known kappa,
# kappa_start, slip_start and kappa_sd and wheel noise (data/examples/simulate.toml:
# 10 squares per direction, 20 back-and-forth runs, 4 figure-eights: 44 runs,
# 44 first starts), then `umbmark diagnose`; prints per seed the verdict and
# castor_swivel's fitted values (the candidate fitted alone, and the
# explanation's joint fit), then the mean, sd and mean relative error of each.
# Usage: bench/castor_first_start_mc.sh [BUILD_DIR] [SEEDS] [FIRST_SEED]
#   (about 4 s per seed on 2 cores)
set -euo pipefail
BUILD=${1:-build}
SEEDS=${2:-20}
FIRST=${3:-1}
KAPPA=${KAPPA:-0.006} KSTART=${KSTART:-0.02} SLIP=${SLIP:-0.003} KSD=${KSD:-0.003}
HERE=$(cd "$(dirname "$0")" && pwd)
WORK=$(mktemp -d "${TMPDIR:-/tmp}/umbmark-castor-mc.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
for ((s = FIRST; s < FIRST + SEEDS; ++s)); do
  "$BUILD/umbmark" simulate "$HERE/../data/examples/simulate.toml" --out "$WORK/c$s" --seed "$s" --kl 0.001 --kr 0.0015 \
    --effect "castor_swivel:kappa=$KAPPA,kappa_start=$KSTART,slip_start=$SLIP,kappa_sd=$KSD" >/dev/null
  "$BUILD/umbmark" diagnose "$WORK/c$s/campaign.toml" --json "$WORK/d$s.json" >/dev/null 2>&1 || true
done
python3 - "$WORK" "$FIRST" "$SEEDS" "$KAPPA" "$KSTART" "$SLIP" "$KSD" <<'PY'
import json, statistics, sys
work, first, n, truth = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), dict(zip(("kappa", "kappa_start", "slip_start", "kappa_sd"), map(float, sys.argv[4:8])))
rows, named = [], 0
print(f"{'seed':>5} {'verdict':<28} {'kappa mrad':>10} {'kappa_start mrad':>16} {'slip_start mm':>13} {'kappa_sd mrad':>13}")
for s in range(first, first + n):
    d = json.load(open(f"{work}/d{s}.json"))
    v = d["verdict"]["effect"]
    named += v == "castor_swivel"
    c = next(c for c in d["candidates"] if c["effect"] == "castor_swivel")
    p = c["params"]
    rows.append(p)
    print(f"{s:>5} {v:<28} {1e3*p['kappa']:>10.2f} {1e3*p['kappa_start']:>16.2f} {1e3*p['slip_start']:>13.2f} {1e3*p['kappa_sd']:>13.2f}")
print(f"verdict castor_swivel: {named}/{n}")
for k, t in truth.items():
    x = [r[k] for r in rows]
    m, sd = statistics.mean(x), statistics.stdev(x)
    print(f"{k:<12} true {t:.4f}  mean {m:.4f}  sd {sd:.4f}  mean error {100*(m/t-1):+.1f} %  sd {100*sd/t:.1f} %")
PY
