"""An arm without an SRDF whose jaw is the last joint of its chain (a Unitree Z1, an SO-100): ``kinema new
config`` makes the jaw the gripper rather than the planning group's last joint, so that Open and Close
Gripper exist and planning moves the arm only."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml

from kinema.cli.main import main

_INERTIA = (
    '<inertial><mass value="1"/>'
    '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
)
_CUBE = '<collision><geometry><box size="0.04 0.04 0.04"/></geometry></collision>'


def urdf(last_joint: str) -> str:
    links = "".join(f'<link name="{name}">{_INERTIA}{_CUBE}</link>' for name in ("l1", "l2", "mover"))
    joints = "".join(
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="0 0 0.2"/><axis xyz="0 1 0"/><limit lower="{low}" upper="{high}" effort="10" '
        'velocity="1"/></joint>'
        for name, parent, child, low, high in (
            ("shoulder", "base", "l1", -1, 1),
            ("elbow", "l1", "l2", -1, 1),
            (last_joint, "l2", "mover", -1.5, 0),
        )
    )
    return f'<?xml version="1.0"?><robot name="jawbot"><link name="base"/>{links}{joints}</robot>'


@pytest.mark.parametrize(
    ("last_joint", "gripper"), [("jointGripper", "jointGripper"), ("Jaw", "Jaw"), ("wrist", None)]
)
def test_a_chain_ending_in_a_joint_named_like_a_jaw_gives_that_joint_to_the_gripper(
    workspace_root: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    last_joint: str,
    gripper: str | None,
) -> None:
    description = tmp_path / "jawbot.urdf"
    description.write_text(urdf(last_joint))
    code = main(["new", "config", "jaw_cell", "--from-urdf", str(description), "-w", str(workspace_root)])
    out = capsys.readouterr().out
    assert code == 0, out
    package = workspace_root / "src" / "jaw_cell"
    config = yaml.safe_load((package / "config" / "config.yaml").read_text())
    objectives = sorted(p.name for p in (package / "objectives").iterdir())
    if gripper is None:  # a wrist is an arm joint: the group keeps it and there is no gripper
        assert "planning group  manipulator: shoulder, elbow, wrist" in out, out
        assert "gripper         none" in out, out
        assert objectives == []
        return
    assert "planning group  manipulator: shoulder, elbow\n" in out, out
    # A revolute jaw opens at its lower limit (as a knuckle does) and closes at its upper one.
    assert f"gripper         {gripper}: open -1.5, closed 0" in out, out
    assert f"note: gripper {gripper!r}: the longest chain's last joint, named like a gripper" in out
    assert config["robot"]["gripper"]["joint"] == gripper
    assert objectives == ["close_gripper.xml", "open_gripper.xml"]
    # One-jaw grippers differ (an SO-ARM closes at its lower limit): the guess says so, and how to fix it.
    assert f"note: gripper {gripper!r} is a revolute jaw: open (-1.5) and closed (0) are a guess" in out
    # The objectives read config.yaml, so swapping the two values there is the whole fix.
    config_file = package / "config" / "config.yaml"
    swapped = re.sub(r"open_position: \S+", "open_position: 0", config_file.read_text())
    config_file.write_text(re.sub(r"closed_position: \S+", "closed_position: -1.5", swapped))
    shown = {}
    for objective in ("Open Gripper", "Close Gripper"):
        assert main(["objective", "show", objective, "-c", "jaw_cell", "-w", str(workspace_root)]) == 0
        shown[objective] = capsys.readouterr().out
    opens = r"position +double = 0  \[from \$\(config robot.gripper.open_position\)\]"
    closes = r"position +double = -1.5  \[from \$\(config robot.gripper.closed_position\)\]"
    assert re.search(opens, shown["Open Gripper"]), shown["Open Gripper"]
    assert re.search(closes, shown["Close Gripper"]), shown["Close Gripper"]
    srdf = (package / "description" / "jaw_cell.srdf").read_text()
    assert '<chain base_link="base" tip_link="l2"/>' in srdf
