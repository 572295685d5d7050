"""benchmarks/own_robot.py in its smoke mode: it still runs and prints its ratios (timings are not judged)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from kinema.config.robot_files import PackageIndex

pytestmark = pytest.mark.slow

BENCHMARK = Path(__file__).resolve().parents[3] / "benchmarks" / "own_robot.py"


def test_the_own_robot_benchmark_runs_in_smoke_mode() -> None:
    if PackageIndex().find("example-robot-data") is None:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data, in the test extra)")
    result = subprocess.run(
        [sys.executable, str(BENCHMARK), "--smoke"], capture_output=True, text=True, timeout=600
    )
    assert result.returncode == 0, result.stdout + result.stderr
    for label in ("new config --from-urdf, meshes converted", "kinema run panda_bench until ready"):
        assert label in result.stdout, result.stdout
    assert "x lab_sim's start" in result.stdout and "x the import floor" in result.stdout
