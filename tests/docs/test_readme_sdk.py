"""The README's SDK example: it passes `mypy --strict` and prints what its comments say against a runtime."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from kinema.transport import free_endpoint

README = Path(__file__).resolve().parents[2] / "README.md"


def sdk_example() -> str:
    """The python block of the README's "Python SDK" section."""
    text = README.read_text(encoding="utf-8")
    section = text.split("## Python SDK", 1)[1]
    found = re.search(r"```python\n(.*?)```", section, re.S)
    assert found, "the README's Python SDK section has no python block"
    return found.group(1)


def test_the_example_is_short() -> None:
    code = [line for line in sdk_example().splitlines() if line.strip()]
    assert len(code) <= 10, code


def test_the_example_passes_mypy_strict(tmp_path: Path) -> None:
    if shutil.which("mypy") is None and not _module_available("mypy"):
        pytest.skip("mypy is not installed (pip install -e '.[test]' installs it)")
    script = tmp_path / "sdk_example.py"
    script.write_text(sdk_example())
    checked = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--no-incremental", str(script)],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp_path,
    )
    assert checked.returncode == 0, checked.stdout + checked.stderr


def _module_available(name: str) -> bool:
    import importlib.util

    return importlib.util.find_spec(name) is not None


@pytest.fixture
def example_config_agent(tmp_path: Path):  # type: ignore[no-untyped-def]
    """An agent for the bundled example_config (its behaviors, wall time, no driver) on a free port."""
    endpoint = free_endpoint()
    read_fd, write_fd = os.pipe()
    log_file = tmp_path / "agent.log"
    argv = [sys.executable, "-m", "kinema.runtime.agent_process", "--host-router", endpoint]
    argv += ["--config", "example_config", "--clock", "wall", "--no-hot-reload", "--log-file", str(log_file)]
    process = subprocess.Popen([*argv, "--ready-fd", str(write_fd)], pass_fds=(write_fd,))
    os.close(write_fd)
    with os.fdopen(read_fd) as ready:
        line = ready.readline().strip()
    try:
        assert line == "ready", log_file.read_text() if log_file.exists() else "the agent did not start"
        yield endpoint
    finally:
        process.terminate()
        try:
            process.wait(10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(5)


def test_the_example_prints_what_it_says(tmp_path: Path, example_config_agent: str) -> None:
    script = tmp_path / "sdk_example.py"
    script.write_text(sdk_example())
    env = {**os.environ, "KINEMA_ZENOH_CONNECT": example_config_agent}
    ran = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, env=env)
    assert ran.returncode == 0, ran.stdout + ran.stderr
    assert ran.stdout.splitlines() == [
        "objective 'Add Numbers' succeeded",
        "42 43 ['Add Numbers']",
        "True",
    ], ran.stdout + ran.stderr
