"""The runtime and the SDK are headless: importing them never imports a UI or 3D library."""

from __future__ import annotations

import subprocess
import sys

import pytest


@pytest.mark.parametrize(
    "module",
    ["kinema.runtime.agent_process", "kinema.runtime.launcher", "kinema.sdk", "kinema.cli.objective"],
)
def test_importing_does_not_pull_in_ui_libraries(module: str) -> None:
    code = (
        f"import sys, {module}, kinema.runtime.agent, kinema.runtime.objective_server\n"
        "print(sorted(m for m in ('textual', 'rich', 'meshcat') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


def test_the_one_shot_cli_client_does_not_load_the_ros_type_system() -> None:
    code = (
        "import sys, kinema.cli.objective, kinema.sdk.quick\n"
        "print('rosbags' in sys.modules, 'numpy' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.stdout.strip() == "False False", done.stderr
