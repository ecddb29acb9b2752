#!/usr/bin/env python3
"""Calibrating a 10^6-sample trajectory from numpy arrays vs from its CSV
(Python module, docs/python.md): wall time and peak memory of each, and
their ratio. Each way runs in its own process (peak RSS is per process);
the arrays are loaded before the clock starts (they are what a notebook
holds), the CSV is read inside the timed call (it is what the file route
costs). Peak memory is given for the Python process (which holds the
arrays) and for the umbmark process the module runs.

    PYTHONPATH=build python3 bench/python_arrays.py [--samples 1000000] [--repeat 3]

Prints one line per way (best of --repeat) and the ratio arrays/CSV; the
target (issue 31) is a ratio <= 1.
"""
import argparse
import json
import os
import pathlib
import resource
import subprocess
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "data" / "examples"


def make_campaign(folder, samples):
    """A simulated square campaign of about `samples` samples (seeded)."""
    import umbmark
    # 20 squares of 1 m per direction; the rate sets the sample count.
    probe = umbmark.simulate(EXAMPLES / "simulate.toml", out=folder / "probe", seed=1, square_runs=20,
                             back_and_forth_runs=1, free_runs=1, sample_rate=20)
    n20 = sum(1 for _ in open(folder / "probe" / "square.csv")) - 1
    rate = 20.0 * samples / n20
    umbmark.simulate(EXAMPLES / "simulate.toml", out=folder / "big", seed=1, square_runs=20,
                     back_and_forth_runs=1, free_runs=1, sample_rate=rate)
    return folder / "big" / "square.csv", rate


def load_arrays(csv_path):
    """The CSV as a list of dicts of numpy arrays, one per run."""
    import numpy as np
    with open(csv_path) as f:  # comment lines (#) before the header
        skip = 0
        while f.readline().startswith("#"):
            skip += 1
    cols = np.genfromtxt(csv_path, delimiter=",", names=True, dtype=None, encoding="utf-8", skip_header=skip)
    runs = []
    ids = cols["run"]
    starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    ends = np.r_[starts[1:], len(ids)]
    for s, e in zip(starts, ends):
        run = {name: np.ascontiguousarray(cols[name][s:e]) for name in cols.dtype.names if name not in ("run", "direction")}
        run["run"] = str(ids[s])
        run["direction"] = str(cols["direction"][s])
        for k in ("ticks_left", "ticks_right"):
            if k in run:
                run[k] = run[k].astype(np.int64)
        runs.append(run)
    return runs


def child(way, csv_path, repeat):
    import umbmark
    robot = EXAMPLES / "robot.toml"
    runs = load_arrays(csv_path) if way == "arrays" else None
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        if way == "arrays":
            r = umbmark.calibrate(runs=runs, robot=robot, side=1.0, no_heldout=True)
        else:
            r = umbmark.calibrate(csv_path, robot=robot, side=1.0, no_heldout=True)
        best = min(best, time.perf_counter() - t0)
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    command_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0  # the umbmark process
    print(json.dumps({"way": way, "seconds": best, "peak_mb": peak_mb, "command_mb": command_mb, "E_d": r.E_d,
                      "E_b": r.E_b}))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--child", nargs=2, metavar=("WAY", "CSV"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        return child(a.child[0], a.child[1], a.repeat)
    with tempfile.TemporaryDirectory() as tmp:
        csv_path, rate = make_campaign(pathlib.Path(tmp), a.samples)
        n = sum(1 for _ in open(csv_path)) - 1
        print(f"trajectory: {n} samples, 40 square runs at {rate:.0f} Hz, {os.path.getsize(csv_path) / 1e6:.0f} MB CSV")
        out = {}
        for way in ("csv", "arrays"):
            p = subprocess.run([sys.executable, __file__, "--repeat", str(a.repeat), "--child", way, str(csv_path)],
                               capture_output=True, text=True, check=True)
            out[way] = json.loads(p.stdout.strip().splitlines()[-1])
            o = out[way]
            print(f"  from {way:<6}  {o['seconds']:7.3f} s (best of {a.repeat})   peak RSS: python {o['peak_mb']:5.0f} MB,"
                  f" umbmark {o['command_mb']:5.0f} MB   E_d {o['E_d']:.9f}")
        assert out["csv"]["E_d"] == out["arrays"]["E_d"] and out["csv"]["E_b"] == out["arrays"]["E_b"]
        ratio = out["arrays"]["seconds"] / out["csv"]["seconds"]
        print(f"  arrays / CSV time ratio {ratio:.3f} ({'no slower' if ratio <= 1.0 else 'SLOWER'}: the module writes "
              f"the checked arrays as a CSV that umbmark then reads)")


if __name__ == "__main__":
    main()
