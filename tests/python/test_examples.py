"""The examples in examples/ run as documented: the factory-line script
passes good robots (their ROS 2 file written) and exits 1 on a failed one
(no file for it); the notebook-style script writes its figure."""
import os
import subprocess
import sys

import pytest

from conftest import EXAMPLES, SOURCE

SCRIPTS = SOURCE / "examples"


def run(script, *args, cwd=None):
    env = dict(os.environ)
    return subprocess.run([sys.executable, str(SCRIPTS / script), *map(str, args)], capture_output=True, text=True,
                          env=env, cwd=cwd, check=False)


def test_factory_line_passes_good_robots(tmp_path):
    p = run("factory_line.py", "--out", tmp_path, "--robot", EXAMPLES / "robot.toml", "--side", "0.75",
            EXAMPLES / "calibrate.toml", EXAMPLES / "endpoints.csv")
    assert p.returncode == 0, p.stdout + p.stderr
    assert "2 of 2 robots pass" in p.stdout
    yaml = (tmp_path / "calibrate.yaml").read_text()
    assert "wheel_separation_multiplier" in yaml


def test_factory_line_fails_a_robot_on_its_threshold(tmp_path):
    # The example robot's wheelbase moves by about 3 %: a 1 % limit fails it.
    p = run("factory_line.py", "--out", tmp_path, "--max-change", "0.01", "--robot", EXAMPLES / "robot.toml",
            "--side", "0.75", EXAMPLES / "calibrate.toml", EXAMPLES / "endpoints.csv")
    assert p.returncode == 1
    assert "FAIL: wheelbase_m changes by" in p.stdout
    assert not any(tmp_path.glob("calibrate*.yaml")) and (tmp_path / "endpoints.yaml").exists()


def test_factory_line_fails_a_robot_with_bad_data(tmp_path):
    bad = SOURCE / "tests" / "data" / "bad" / "ep_nan.csv"
    p = run("factory_line.py", "--out", tmp_path, "--robot", EXAMPLES / "robot.toml", "--side", "0.75",
            EXAMPLES / "endpoints.csv", bad)
    assert p.returncode == 1
    assert "InputError" in p.stdout and "1 of 2 robots pass" in p.stdout
    assert (tmp_path / "endpoints.yaml").exists() and not (tmp_path / "ep_nan.yaml").exists()


def test_notebook_plot_writes_its_figure(tmp_path):
    pytest.importorskip("matplotlib")
    pytest.importorskip("numpy")
    out = tmp_path / "fig.png"
    p = run("notebook_plot.py", "--out", out)
    assert p.returncode == 0, p.stdout + p.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 20000
    assert "E_d = " in p.stdout
