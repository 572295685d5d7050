"""The benchmarks that have a smoke mode run in the suite: they keep working as the code changes.

Their figures are printed, never asserted (STYLE.md: tests never assert wall-clock speed).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[3] / "benchmarks"


@pytest.mark.parametrize("script", ["large_values.py", "soak.py"])
def test_a_benchmark_runs_in_smoke_mode(script: str) -> None:
    done = subprocess.run(
        [sys.executable, str(BENCHMARKS / script), "--smoke"],
        capture_output=True,
        text=True,
        cwd=BENCHMARKS,
        env={**os.environ, "PYTHONPATH": str(BENCHMARKS)},
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    assert done.stdout.strip(), "the benchmark printed no figures"
