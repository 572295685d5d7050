"""Fixtures for the template tests: an empty workspace, and one with a config package of its own."""

from __future__ import annotations

from pathlib import Path

import pytest

CONFIG_YAML = """\
# my_config: the robot config of this test workspace.
based_on_package: "example_config"
# A line longer than 80 characters, as a generated robot config writes its planning group's joints:
robot_notes: [shoulder_pan_joint, shoulder_lift_joint, elbow_joint, wrist_1_joint, wrist_2_joint]

objectives:
  # Our own objectives.
  objective_library_paths:
    my_config_objectives:
      package_name: "my_config"
      relative_path: "objectives"

  # More behaviors go here.
"""


@pytest.fixture
def workspace(tmp_path: Path) -> Path:
    """An empty workspace (a folder with ``src/``)."""
    (tmp_path / "ws" / "src").mkdir(parents=True)
    return tmp_path / "ws"


@pytest.fixture
def workspace_with_config(workspace: Path) -> Path:
    """A workspace holding config package ``my_config`` (based on the bundled example_config)."""
    package = workspace / "src" / "my_config"
    (package / "config").mkdir(parents=True)
    (package / "objectives").mkdir()
    (package / "config" / "config.yaml").write_text(CONFIG_YAML)
    (package / "package.xml").write_text("<package><name>my_config</name></package>\n")
    return workspace
