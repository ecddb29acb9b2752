#!/usr/bin/env python3
"""Notebook-style: a calibration from numpy arrays, then the pose
uncertainty it leaves, in one matplotlib figure.

    python3 examples/notebook_plot.py [TRAJECTORY.csv ROBOT.toml SIDE_M] [--out FIG.png]

Cells, as in a notebook:
 1. load a trajectory CSV into numpy arrays (one dict of columns per run);
 2. calibrate from the arrays (umbmark.calibrate(runs=...));
 3. plot each run's return error before and after the correction;
 4. predict the pose covariance along a 5 m line (closed form, Chong &
    Kleeman) and plot its 1-sigma ellipse over 2,000 Monte Carlo end poses.
Uses numpy and matplotlib from Debian (python3-numpy, python3-matplotlib).
"""
import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files, no display
import matplotlib.pyplot as plt
import numpy as np

import umbmark

HERE = pathlib.Path(__file__).resolve().parent
ap = argparse.ArgumentParser(description="calibrate from arrays and plot")
ap.add_argument("csv", nargs="?", default=HERE.parent / "data/examples/square_ticks.csv")
ap.add_argument("robot", nargs="?", default=HERE.parent / "data/examples/robot.toml")
ap.add_argument("side", nargs="?", type=float, default=1.0)
ap.add_argument("--out", default="notebook_plot.png")
a = ap.parse_args()

# %% 1. The trajectory CSV as arrays, one dict per run.
with open(a.csv) as f:  # comment lines (#) may come before the header
    skip = 0
    while f.readline().startswith("#"):
        skip += 1
table = np.genfromtxt(a.csv, delimiter=",", names=True, dtype=None, encoding="utf-8", skip_header=skip)
runs = []
for run_id in dict.fromkeys(table["run"]):  # in file order
    rows = table[table["run"] == run_id]
    runs.append({name: rows[name] for name in table.dtype.names})
print(f"{len(runs)} runs, {sum(len(r['t_s']) for r in runs)} samples")

# %% 2. Calibrate from the arrays.
cal = umbmark.calibrate(runs=runs, robot=a.robot, side=a.side)
p = cal.parameters
print(f"E_d = {cal.E_d:.5f}, E_b = {cal.E_b:.5f}; wheelbase {p['wheelbase_m']:.5f} m, "
      f"D_L {p['wheel_diameter_left_m']:.5f} m, D_R {p['wheel_diameter_right_m']:.5f} m")

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 5))
# %% 3. Return errors before and after the correction.
before = {d: np.array([(r["ex_m"], r["ey_m"]) for r in cal.runs if r["direction"] == d]) for d in ("cw", "ccw")}
after = cal.to_dict().get("evaluation", {}).get("after_runs", [])
for d, marker in (("cw", "o"), ("ccw", "s")):
    ax1.scatter(1000 * before[d][:, 0], 1000 * before[d][:, 1], marker=marker, label=f"{d} before")
ax1.set(title=f"Return errors, {len(cal.runs)} squares of {a.side:g} m", xlabel="x error [mm]", ylabel="y error [mm]")
ax1.axhline(0, color="0.8", lw=0.5)
ax1.axvline(0, color="0.8", lw=0.5)
ax1.legend()
ax1.text(0.02, 0.02, f"E_max,syst before {1000 * cal.E_max_syst_m:.0f} mm"
         + (f", after {1000 * cal.evaluation['E_max_syst_after_m']:.0f} mm" if "evaluation" in cal else ""),
         transform=ax1.transAxes)

# %% 4. The uncertainty left: predicted covariance after a 5 m line.
pred = umbmark.predict(robot=a.robot, wheelbase=p["wheelbase_m"], kl=1e-3, kr=1e-3, path="line:5",
                       monte_carlo=2000, seed=1, threads=1)
P = np.array(pred.covariance)[:2, :2]
w, v = np.linalg.eigh(P)
t = np.linspace(0, 2 * np.pi, 200)
ellipse = (v @ np.diag(np.sqrt(w)) @ np.array([np.cos(t), np.sin(t)])).T + np.array(pred.mean[:2])
mc = pred.monte_carlo
ax2.plot(ellipse[:, 0], 1000 * ellipse[:, 1], label="closed form, 1 sigma")
Pmc = np.array(mc["covariance"])[:2, :2]
w2, v2 = np.linalg.eigh(Pmc)
ellipse2 = (v2 @ np.diag(np.sqrt(w2)) @ np.array([np.cos(t), np.sin(t)])).T + np.array(mc["mean"][:2])
ax2.plot(ellipse2[:, 0], 1000 * ellipse2[:, 1], "--", label=f"Monte Carlo ({mc['runs']} runs, seed {mc['seed']}), 1 sigma")
ax2.set(title="End pose after a 5 m line, k_L = k_R = 1e-3 m^1/2", xlabel="x [m]", ylabel="y [mm]")
ax2.legend()
fig.tight_layout()
fig.savefig(a.out, dpi=100)
print(f"wrote {a.out}")
