#!/usr/bin/env python3
"""Factory line: calibrate a batch of robots, gate each on thresholds, write
the ROS 2 parameter file (diff_drive_controller) of every robot that passes,
and exit 1 when any robot fails.

    python3 examples/factory_line.py --out calibrated/ campaign1.toml campaign2.toml
    python3 examples/factory_line.py --out calibrated/ --robot robot.toml --side 0.75 endpoints.csv

Each input is one robot: a campaign manifest (as `umbmark import` writes
it) or a run CSV with --robot and --side. The gates (see --help):
  - the calibration ran (no input error, no failed quality gate);
  - no corrected parameter moves more than --max-change from the recorded
    one (a larger correction means a mechanical fault, not a calibration);
  - with trajectory input, the systematic error left after the correction
    (E_max,syst after, Borenstein & Feng eq. 3.4) is at most --max-error-after.
A robot that fails gets no parameter file. Uses only the Python standard
library and the umbmark module (docs/python.md).
"""
import argparse
import os
import pathlib
import sys

import umbmark


def gate(result, max_change, max_error_after):
    """The reasons the robot fails (empty: it passes)."""
    reasons = []
    used = result["outputs_use"]["parameters"]
    recorded = result["recorded_parameters"]
    for key in ("wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m"):
        change = used[key] / recorded[key] - 1.0
        if abs(change) > max_change:
            reasons.append(f"{key} changes by {100 * change:+.2f} % (limit {100 * max_change:.2f} %)")
    evaluation = result.to_dict().get("evaluation")
    if evaluation is not None and evaluation["E_max_syst_after_m"] > max_error_after:
        reasons.append(f"E_max,syst after correction {1000 * evaluation['E_max_syst_after_m']:.1f} mm "
                       f"(limit {1000 * max_error_after:.1f} mm)")
    return reasons


def robot_name(path):
    """The robot's name: the input's stem, or its folder for a generic name."""
    p = pathlib.Path(path)
    return p.parent.name if p.stem in ("campaign", "runs") and p.parent.name else p.stem


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("inputs", nargs="+", help="one manifest or run CSV per robot")
    ap.add_argument("--out", required=True, help="folder for the ROS 2 parameter files of the robots that pass")
    ap.add_argument("--robot", help="robot TOML for CSV inputs")
    ap.add_argument("--side", type=float, help="square side [m] for CSV inputs")
    ap.add_argument("--max-change", type=float, default=0.05,
                    help="largest relative change of a parameter from the recorded one (default 0.05 = 5 %%)")
    ap.add_argument("--max-error-after", type=float, default=0.02,
                    help="largest E_max,syst after correction [m], trajectory input (default 0.02)")
    a = ap.parse_args(argv)
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)

    failed = 0
    print(f"{'robot':<24} {'wheelbase [m]':>13} {'D left [m]':>11} {'D right [m]':>11}  verdict")
    for path in a.inputs:
        name = robot_name(path)
        yaml = out / f"{name}.yaml"
        staged = out / f".{name}.yaml.staged"
        options = {} if path.endswith(".toml") else {"robot": a.robot, "side": a.side}
        try:
            r = umbmark.calibrate(path, ros2=staged, **options)
            reasons = gate(r, a.max_change, a.max_error_after)
        except umbmark.Error as e:  # InputError, UsageError, QualityGateError
            r, reasons = None, [f"{type(e).__name__}: {e}"]
        if reasons:
            failed += 1
            staged.unlink(missing_ok=True)
            yaml.unlink(missing_ok=True)  # never leave an earlier pass's file for a robot that now fails
            print(f"{name:<24} {'':>13} {'':>11} {'':>11}  FAIL: " + "; ".join(reasons))
            continue
        os.replace(staged, yaml)
        p = r["outputs_use"]["parameters"]
        print(f"{name:<24} {p['wheelbase_m']:>13.5f} {p['wheel_diameter_left_m']:>11.5f} "
              f"{p['wheel_diameter_right_m']:>11.5f}  pass -> {yaml}")
    print(f"{len(a.inputs) - failed} of {len(a.inputs)} robots pass")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
