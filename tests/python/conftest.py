"""Fixtures of the Python module's tests: the source tree, the command-line
binary the results are compared with, and a runner for it.

ctest runs this suite (CMakeLists.txt, test `python_module`) with
PYTHONPATH set to the build folder and UMBMARK_EXE / UMBMARK_SOURCE_DIR set.
"""
import json
import math
import os
import pathlib
import subprocess

import pytest

SOURCE = pathlib.Path(os.environ.get("UMBMARK_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
EXE = os.environ.get("UMBMARK_EXE", str(SOURCE / "build" / "umbmark"))
EXAMPLES = SOURCE / "data" / "examples"

# The keys whose values are wall-clock measurements (never compared; the
# contract names the first three, solve_time_s is the refined fit's solver time).
TIMING_KEYS = {"timing_s", "seconds", "steps_per_second", "solve_time_s"}


def run_cli(*args):
    """Runs the command-line umbmark; returns (exit status, stdout, stderr)."""
    p = subprocess.run([EXE, *map(str, args)], capture_output=True, text=True, check=False)
    return p.returncode, p.stdout, p.stderr


def cli_json(*args):
    """The JSON `umbmark ARGS --json -` prints (exit status 0 required)."""
    status, out, err = run_cli(*args, "--json", "-")
    assert status == 0, err
    return json.loads(out)


def assert_same(a, b, path="$", rel=1e-12):
    """Equal JSON values, numbers to `rel` (relative, absolute near 0); the
    timing keys are skipped."""
    if isinstance(a, dict):
        assert isinstance(b, dict), path
        assert set(a) - TIMING_KEYS == set(b) - TIMING_KEYS, f"{path}: keys differ: {set(a) ^ set(b)}"
        for k in a:
            if k not in TIMING_KEYS:
                assert_same(a[k], b[k], f"{path}.{k}", rel)
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{path}: lengths differ"
        for i, (x, y) in enumerate(zip(a, b)):
            assert_same(x, y, f"{path}[{i}]", rel)
    elif isinstance(a, float) or isinstance(b, float):
        assert isinstance(a, (int, float)) and isinstance(b, (int, float)), f"{path}: {a!r} vs {b!r}"
        assert math.isclose(a, b, rel_tol=rel, abs_tol=rel), f"{path}: {a!r} vs {b!r}"
    else:
        assert a == b, f"{path}: {a!r} vs {b!r}"


@pytest.fixture
def examples():
    return EXAMPLES
