#!/usr/bin/env python3
"""Calibrating a 10^6-sample trajectory from numpy arrays vs from its CSV
(Python module, docs/python.md): wall time (median of --repeat calls) and
peak memory of each way, and their ratio. Both run in the Python process
(umbmark.calibrate is in-process: the arrays go to the library without a
file, the CSV is read by the library's reader); the command line on the
same CSV is timed for reference.

Each way runs in a child process of its own, so its peak RSS is its own.
The arrays are loaded from an .npz before the clock starts (they are what a
notebook holds); the CSV is read inside the timed call (it is what the file
route costs).

    PYTHONPATH=build python3 bench/python_arrays.py [--samples 1000000] [--repeat 5]

The target (issue 31) is an arrays / CSV time ratio <= 1. A benchmark, not
a test: nothing here is asserted except that every way gives the same E_d
and E_b.
"""
import argparse
import json
import os
import pathlib
import resource
import statistics
import subprocess
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "data" / "examples"
ROBOT = EXAMPLES / "robot.toml"


def make_campaign(folder, samples):
    """A simulated square campaign of about `samples` samples (seeded)."""
    import umbmark
    # 20 squares of 1 m per direction; the rate sets the sample count.
    umbmark.simulate(EXAMPLES / "simulate.toml", out=folder / "probe", seed=1, square_runs=20,
                     back_and_forth_runs=1, free_runs=1, sample_rate=20)
    n20 = sum(1 for _ in open(folder / "probe" / "square.csv")) - 1
    rate = 20.0 * samples / n20
    umbmark.simulate(EXAMPLES / "simulate.toml", out=folder / "big", seed=1, square_runs=20,
                     back_and_forth_runs=1, free_runs=1, sample_rate=rate)
    return folder / "big" / "square.csv", rate


def csv_to_npz(csv_path, npz_path):
    """The CSV's columns as numpy arrays (float64; ticks int64; run and
    direction as text), saved for the arrays child."""
    import numpy as np
    with open(csv_path) as f:  # comment lines (#) before the header
        skip = 0
        while f.readline().startswith("#"):
            skip += 1
    cols = np.genfromtxt(csv_path, delimiter=",", names=True, dtype=None, encoding="utf-8", skip_header=skip)
    arrays = {}
    for name in cols.dtype.names:
        a = cols[name]
        if name.startswith("ticks_"):
            a = a.astype(np.int64)
        elif name not in ("run", "direction"):
            a = a.astype(np.float64)
        else:
            a = a.astype(str)
        arrays[name] = np.ascontiguousarray(a)
    np.savez(npz_path, **arrays)


def load_runs(npz_path):
    """The arrays as a list of dicts, one per run (views, no copies)."""
    import numpy as np
    cols = dict(np.load(npz_path))
    ids = cols["run"]
    starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    ends = np.r_[starts[1:], len(ids)]
    runs = []
    for s, e in zip(starts, ends):
        run = {k: v[s:e] for k, v in cols.items() if k not in ("run", "direction")}
        run["run"] = str(ids[s])
        run["direction"] = str(cols["direction"][s])
        runs.append(run)
    return runs


def peak_mb(who=resource.RUSAGE_SELF):
    """Peak RSS [MB]: this process' VmHWM (getrusage's ru_maxrss would carry
    the parent's peak across fork + exec), or its children's."""
    if who == resource.RUSAGE_SELF:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    return resource.getrusage(who).ru_maxrss / 1024.0


def child(way, data, repeat):
    """One way, timed `repeat` times; prints a JSON line."""
    import umbmark
    runs = load_runs(data) if way == "arrays" else None
    before_mb = peak_mb()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        if way == "arrays":
            r = umbmark.calibrate(runs=runs, robot=ROBOT, side=1.0, no_heldout=True).to_dict()
        elif way == "csv":
            r = umbmark.calibrate(data, robot=ROBOT, side=1.0, no_heldout=True).to_dict()
        else:  # the command line, for reference
            p = subprocess.run([os.environ.get("UMBMARK_EXE", str(HERE.parent / "build" / "umbmark")), "calibrate",
                                data, "--robot", str(ROBOT), "--side", "1", "--no-heldout", "--json", "-"],
                               capture_output=True, text=True, check=True)
            r = json.loads(p.stdout)
        times.append(time.perf_counter() - t0)
    peak = peak_mb(resource.RUSAGE_CHILDREN) if way == "cli" else peak_mb()
    print(json.dumps({"way": way, "median_s": statistics.median(times), "min_s": min(times), "max_s": max(times),
                      "before_mb": before_mb, "peak_mb": peak, "E_d": r["E_d"], "E_b": r["E_b"]}))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--child", nargs=2, metavar=("WAY", "DATA"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        return child(a.child[0], a.child[1], a.repeat)
    with tempfile.TemporaryDirectory() as tmp:
        csv_path, rate = make_campaign(pathlib.Path(tmp), a.samples)
        npz_path = pathlib.Path(tmp) / "arrays.npz"
        csv_to_npz(csv_path, npz_path)
        n = sum(1 for _ in open(csv_path)) - 1
        print(f"trajectory: {n} samples, 40 square runs at {rate:.0f} Hz, {os.path.getsize(csv_path) / 1e6:.0f} MB CSV;"
              f" umbmark.calibrate(..., no_heldout=True), median of {a.repeat} calls")
        out = {}
        for way, data in (("arrays", npz_path), ("csv", csv_path), ("cli", csv_path)):
            p = subprocess.run([sys.executable, __file__, "--repeat", str(a.repeat), "--child", way, str(data)],
                               capture_output=True, text=True, check=True)
            o = out[way] = json.loads(p.stdout.strip().splitlines()[-1])
            what = {"arrays": "numpy arrays, in-process", "csv": "CSV file, in-process",
                    "cli": "CSV file, command line"}[way]
            mem = (f"peak RSS {o['peak_mb']:5.0f} MB (umbmark process)" if way == "cli" else
                   f"peak RSS {o['peak_mb']:5.0f} MB ({o['before_mb']:.0f} MB before the first call)")
            print(f"  {what:<26} {o['median_s']:7.3f} s (min {o['min_s']:.3f}, max {o['max_s']:.3f})   {mem}"
                  f"   E_d {o['E_d']:.12f}")
        same = all(out[w]["E_d"] == out["csv"]["E_d"] and out[w]["E_b"] == out["csv"]["E_b"] for w in out)
        ratio = out["arrays"]["median_s"] / out["csv"]["median_s"]
        print(f"  arrays / CSV time ratio {ratio:.3f} ({'no slower' if ratio <= 1.0 else 'SLOWER'});"
              f" CLI / in-process CSV {out['cli']['median_s'] / out['csv']['median_s']:.3f};"
              f" same E_d, E_b every way: {same}")
        return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
