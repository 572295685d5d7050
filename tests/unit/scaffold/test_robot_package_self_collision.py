"""A robot whose links overlap at Home: ``kinema new config`` and ``kinema build`` say so, and a generated
SRDF disables the pair as MoveIt's setup assistant does (reason ``Default``: links that touch by design).

The robot: a base, an upright link, and a last link hanging back down into the base at every joint at 0
(as the Unitree Z1 folds its wrist onto its upper arm in example-robot-data's URDF).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from kinema.cli.main import main

_INERTIA = (
    '<inertial><mass value="1"/>'
    '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
)
_CUBE = '<collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision>'
_LIMIT = '<limit lower="-1" upper="1" effort="10" velocity="1"/>'
URDF = f"""<?xml version="1.0"?>
<robot name="folder">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="upper">{_INERTIA}{_CUBE}</link>
  <link name="hanging">{_INERTIA}{_CUBE}</link>
  <joint name="turn" type="revolute">
    <parent link="base"/><child link="upper"/><origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>{_LIMIT}
  </joint>
  <joint name="wrist" type="revolute">
    <parent link="upper"/><child link="hanging"/><origin xyz="0 0 -0.3"/><axis xyz="1 0 0"/>{_LIMIT}
  </joint>
</robot>
"""
SRDF = """<?xml version="1.0"?>
<robot name="folder">
  <group name="arm"><joint name="turn"/><joint name="wrist"/></group>
  <disable_collisions link1="base" link2="upper" reason="Adjacent"/>
  <disable_collisions link1="upper" link2="hanging" reason="Adjacent"/>
</robot>
"""
DEFAULT_PAIR = '<disable_collisions link1="base" link2="hanging" reason="Default"/>'


@pytest.fixture
def robot(tmp_path: Path) -> Path:
    folder = tmp_path / "folder_description"
    folder.mkdir()
    (folder / "folder.urdf").write_text(URDF)
    (folder / "folder.srdf").write_text(SRDF)
    return folder


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out + captured.err


def test_a_generated_srdf_disables_the_pairs_that_overlap_at_home(
    workspace_root: Path, robot: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ws, urdf = str(workspace_root), str(robot / "folder.urdf")
    code, out = run(capsys, "new", "config", "folder_cell", "--from-urdf", urdf, "-w", ws)
    assert code == 0, out
    assert (
        "note: 1 link pair(s) in collision at Home are disabled in the SRDF (reason Default, as MoveIt's "
        "setup assistant does: links that touch by design): base - hanging"
    ) in out
    srdf = (workspace_root / "src" / "folder_cell" / "description" / "folder_cell.srdf").read_text()
    assert DEFAULT_PAIR in srdf
    assert '<disable_collisions link1="base" link2="upper" reason="Adjacent"/>' in srdf
    code, out = run(capsys, "build", "--skip-install", "-w", ws, "-c", "folder_cell")
    assert code == 0, out
    assert "self-collision" not in out, out


def test_a_given_srdf_that_leaves_home_in_self_collision_is_flagged_by_new_config_and_build(
    workspace_root: Path, robot: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ws = str(workspace_root)
    urdf, srdf = str(robot / "folder.urdf"), str(robot / "folder.srdf")
    code, out = run(capsys, "new", "config", "folder_cell", "--from-urdf", urdf, "--srdf", srdf, "-w", ws)
    assert code == 0, out
    assert (
        "note: Home is in self-collision (base - hanging): no motion can start or end there. If these links "
        f"touch by design, disable the pair in the SRDF: {DEFAULT_PAIR}"
    ) in out
    package = workspace_root / "src" / "folder_cell"
    # The user's SRDF is theirs: it is copied as given, not amended.
    assert DEFAULT_PAIR not in (package / "description" / "folder_cell.srdf").read_text()
    code, out = run(capsys, "build", "--skip-install", "-w", ws, "-c", "folder_cell")
    assert code == 0, out  # a warning: the waypoint may be there on purpose, and nothing else is wrong
    waypoints = package / "waypoints" / "waypoints.yaml"
    line = next(n for n, text in enumerate(waypoints.read_text().splitlines(), 1) if "name: 'Home'" in text)
    assert (
        f"warning: {waypoints}:{line}: waypoint 'Home' is in self-collision (base - hanging): no motion can "
        f"start or end there. If these links touch by design, disable the pair in folder_cell.srdf: "
        f"{DEFAULT_PAIR}"
    ) in out
