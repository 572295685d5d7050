"""Every benchmark in ``benchmarks/`` runs in its smoke mode in the suite, so none can rot.

A benchmark that listens for a message type the runtime stopped publishing, or calls an API that changed,
fails here instead of on the day someone wants a figure. Each run must print the line with its ratio to
the peer measured in the same run; the figures themselves are never asserted (STYLE.md: tests never
assert wall-clock speed).
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

BENCHMARKS = Path(__file__).resolve().parents[3] / "benchmarks"

# script -> text of the line that gives its ratio to the peer
RATIO_LINES = {
    "bt_tick.py": "ratio = BT.CPP rate / Kinema rate",
    "cancel_latency.py": "vs peer",
    "cli_start.py": "ratio to python -c pass",
    "config_resolve.py": "ratio kinema / peer",
    "hot_reload.py": "restart / hot reload",
    "large_values.py": "cancel vs peer",
    "motion.py": "RRTConnect forced",
    "perception.py": "MuJoCo's Renderer.render",
    "pick_and_place.py": "objective / plain script",
    "sdk_latency.py": "p50 / floor",
    "sim_driver.py": "of the floor",
    "soak.py": "ratio",
    "task_planning.py": "task / separate calls",
    "transport_rtt.py": "Kinema call / raw query",
    "tui.py": "ratio kinema ui / bare Textual",
    "viewer.py": "drop with the view on",
}
# Scripts in benchmarks/ that are not benchmarks, or whose smoke run another test owns (and why).
NOT_HERE = {
    "latency.py": "timing helpers imported by sdk_latency.py and transport_rtt.py",
    "headless_cell.py": "starts `kinema run --headless` for cli_start.py and soak.py",
    "own_robot.py": "tests/sim/own_robot/test_own_robot_benchmark.py (needs example-robot-data)",
}
# script -> (importable module, why the benchmark needs it)
NEEDS = {
    "bt_tick.py": [
        ("behaviortreepy", "BT.CPP, the peer (pip install -e '.[test]')"),
        ("py_trees", "py_trees, the second peer (pip install py_trees)"),
    ],
}


def test_every_benchmark_has_a_smoke_run_here_or_in_a_named_test() -> None:
    scripts = {path.name for path in BENCHMARKS.glob("*.py")}
    assert scripts == set(RATIO_LINES) | set(NOT_HERE), "add the new benchmark's --smoke run to RATIO_LINES"


@pytest.mark.timeout(600)
@pytest.mark.parametrize("script", sorted(RATIO_LINES))
def test_a_benchmark_runs_in_smoke_mode(script: str, tmp_path: Path) -> None:
    for module, why in NEEDS.get(script, []):
        if importlib.util.find_spec(module) is None:
            pytest.skip(f"{script} needs {module}: {why}")
    # Private user folders: a benchmark that starts `kinema run` must not meet the user's runtime or config.
    xdg = {
        name: str(tmp_path / name.lower()) for name in ("XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_STATE_HOME")
    }
    runtime_dir = tmp_path / "run"
    runtime_dir.mkdir(mode=0o700)
    done = subprocess.run(
        [sys.executable, str(BENCHMARKS / script), "--smoke"],
        capture_output=True,
        text=True,
        cwd=BENCHMARKS,
        env={**os.environ, **xdg, "XDG_RUNTIME_DIR": str(runtime_dir), "PYTHONPATH": str(BENCHMARKS)},
        timeout=540,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    assert RATIO_LINES[script] in done.stdout, f"{script} printed no ratio to its peer:\n{done.stdout}"
