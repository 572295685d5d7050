"""``kinema new behavior`` refuses names that would shadow a standard-library or installed module."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from kinema.config import Workspace
from kinema.errors import ScaffoldError
from kinema.scaffold.behavior_package import new_behavior


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("os", "'os' is a module of Python's standard library"),
        ("json", "'json' is a module of Python's standard library"),
        ("yaml", "'yaml' is an installed Python module"),
        ("numpy", "'numpy' is an installed Python module"),
    ],
)
def test_a_module_name_python_already_has_is_refused_before_anything_is_written(
    workspace: Path, name: str, message: str
) -> None:
    with pytest.raises(ScaffoldError, match=f"{message}.*choose another behavior name, e.g. my_{name}"):
        new_behavior(name, "sync", workspace=Workspace.discover(workspace))
    assert list((workspace / "src").iterdir()) == []


def test_the_cli_says_so_in_one_line_without_a_traceback(workspace: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "kinema", "new", "behavior", "os", "-w", str(workspace)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 1, result
    assert "standard library" in result.stderr and "Traceback" not in result.stderr + result.stdout
    assert list((workspace / "src").iterdir()) == []
