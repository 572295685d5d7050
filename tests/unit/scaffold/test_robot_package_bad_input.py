"""``kinema new config NAME --from-urdf URDF`` given bad input: one clear error, and nothing half-written.

Each case runs the command as a user types it and checks the message, the exit code, and that the
workspace's ``src/`` holds exactly what it held before (no package folder, no leftover staging folder).
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import pytest

from kinema.cli.main import main

LFS_POINTER = (
    "version https://git-lfs.github.com/spec/v1\n"
    "oid sha256:4d7a214614ab2935c943f9e0ff69d22eadbb8f32b1258daaa5e2ca24d17e2393\n"
    "size 12345\n"
)
#: A tetrahedron as text STL (the format many CAD exports write; MuJoCo reads only binary STL).
_CORNERS = ((0, 0, 0), (0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1))
STL = (
    "solid tetra\n"
    + "".join(
        "facet normal 0 0 0\nouter loop\n"
        + "".join(f"vertex {x} {y} {z}\n" for x, y, z in (_CORNERS[i] for i in face))
        + "endloop\nendfacet\n"
        for face in ((0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3))
    )
    + "endsolid tetra\n"
)


def urdf_text(mesh: str = "meshes/link.stl", kind: str = "revolute") -> str:
    limit = '<limit lower="-1" upper="1" effort="10" velocity="1"/>' if kind != "fixed" else ""
    return f"""<?xml version="1.0"?>
<robot name="bot">
  <link name="base"/>
  <link name="arm">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="{mesh}"/></geometry></visual>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <joint name="shoulder" type="{kind}">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>{limit}
  </joint>
</robot>
"""


@pytest.fixture
def robot(tmp_path: Path) -> Path:
    """A one-joint robot whose URDF names meshes/link.stl (present)."""
    folder = tmp_path / "bot_description"
    (folder / "meshes").mkdir(parents=True)
    (folder / "meshes" / "link.stl").write_text(STL)
    (folder / "bot.urdf").write_text(urdf_text())
    return folder


def new_config(
    workspace_root: Path, name: str, urdf: Path, *extra: str, capsys: pytest.CaptureFixture[str]
) -> tuple[int, str]:
    code = main(["new", "config", name, "--from-urdf", str(urdf), "-w", str(workspace_root), *extra])
    captured = capsys.readouterr()
    return code, captured.out + captured.err


def listing(folder: Path) -> list[str]:
    """Every path under ``folder``, hidden ones included (a staging folder starts with a dot)."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def test_a_good_robot_is_made(workspace_root: Path, robot: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The baseline the failures are measured against: the same robot, nothing wrong, makes a package."""
    code, out = new_config(workspace_root, "bot_cell", robot / "bot.urdf", capsys=capsys)
    assert code == 0, out
    assert [p.name for p in (workspace_root / "src").iterdir()] == ["bot_cell"]


def _missing_mesh(robot: Path) -> tuple[Path, tuple[str, ...], str]:
    (robot / "meshes" / "link.stl").unlink()
    return robot / "bot.urdf", (), f"link 'arm' (visual): mesh not found: {robot / 'meshes' / 'link.stl'}"


def _lfs_pointer(robot: Path) -> tuple[Path, tuple[str, ...], str]:
    (robot / "meshes" / "link.stl").write_text(LFS_POINTER)
    mesh = robot / "meshes" / "link.stl"
    return robot / "bot.urdf", (), f"mesh {mesh} is a Git LFS pointer file (run `git lfs pull`)"


def _srdf_not_fitting(body: str, problem: str) -> Callable[[Path], tuple[Path, tuple[str, ...], str]]:
    """A case: the URDF, an SRDF of ``body`` naming what the URDF lacks, and the error's ``problem``."""

    def make(robot: Path) -> tuple[Path, tuple[str, ...], str]:
        srdf = robot / "bot.srdf"
        srdf.write_text(f'<robot name="bot">{body}</robot>')
        message = f"{srdf}: the SRDF does not fit the URDF bot.urdf: {problem}"
        return robot / "bot.urdf", ("--srdf", str(srdf)), message

    return make


_srdf_names_other_joints = _srdf_not_fitting(
    '<group name="arm"><joint name="shoulder"/><joint name="elbow"/></group>'
    '<group_state name="home" group="arm"><joint name="wrist" value="0"/></group_state>',
    "group 'arm' names joint 'elbow'; group state 'home' (arm) names joint 'wrist'. "
    "The URDF's joints: shoulder. Fix the SRDF, or leave out --srdf: an SRDF is then made from the URDF",
)
_srdf_chain_upside_down = _srdf_not_fitting(
    '<group name="arm"><chain base_link="arm" tip_link="base"/></group>',
    "group 'arm' chain's tip 'base' is not below its base 'arm'.",
)
_srdf_chain_names_no_link = _srdf_not_fitting(
    '<group name="arm"><chain base_link="world" tip_link="arm"/></group>',
    "group 'arm' chain names link 'world'. The URDF's links: arm, base",
)


def _xacro_error(robot: Path) -> tuple[Path, tuple[str, ...], str]:
    xacro = robot / "bot.urdf.xacro"
    text = urdf_text().replace(
        '<robot name="bot">', '<robot name="bot" xmlns:xacro="http://www.ros.org/wiki/xacro">'
    )
    xacro.write_text(text.replace('effort="10"', 'effort="${max_effort}"'))
    return xacro, (), f"{xacro}: xacro failed: name 'max_effort' is not defined"


def _no_movable_joints(robot: Path) -> tuple[Path, tuple[str, ...], str]:
    (robot / "bot.urdf").write_text(urdf_text(kind="fixed"))
    return (
        robot / "bot.urdf",
        (),
        f"{robot / 'bot.urdf'}: the URDF has no movable joints (revolute, continuous or prismatic): nothing "
        "to plan or simulate",
    )


@pytest.mark.parametrize(
    "make",
    [
        _missing_mesh,
        _lfs_pointer,
        _srdf_names_other_joints,
        _srdf_chain_upside_down,
        _srdf_chain_names_no_link,
        _xacro_error,
        _no_movable_joints,
    ],
    ids=[
        "missing mesh",
        "LFS pointer mesh",
        "SRDF joints",
        "SRDF chain",
        "SRDF chain link",
        "xacro error",
        "no movable joints",
    ],
)
def test_bad_input_is_one_clear_error_and_writes_nothing(
    workspace_root: Path, robot: Path, make: object, capsys: pytest.CaptureFixture[str]
) -> None:
    urdf, extra, message = make(robot)  # type: ignore[operator]
    before = listing(workspace_root)
    code, out = new_config(workspace_root, "bot_cell", urdf, *extra, capsys=capsys)
    assert code == 1
    assert message in out, out
    assert out.count("error:") == 1 and "Traceback" not in out
    assert listing(workspace_root) == before


@pytest.mark.parametrize("taken", ["workspace package", "bundled package", "folder"])
def test_a_name_already_taken_is_refused_before_anything_is_read(
    workspace_root: Path, robot: Path, taken: str, capsys: pytest.CaptureFixture[str]
) -> None:
    src = workspace_root / "src"
    name = {"workspace package": "bot_cell", "bundled package": "lab_sim", "folder": "bot_cell"}[taken]
    if taken == "workspace package":
        assert new_config(workspace_root, name, robot / "bot.urdf", capsys=capsys)[0] == 0
    elif taken == "folder":
        (src / name).mkdir()
        (src / name / "notes.txt").write_text("mine")
    before = listing(workspace_root)
    shutil.rmtree(robot / "meshes")  # the robot is not even read: the name is refused first
    code, out = new_config(workspace_root, name, robot / "bot.urdf", capsys=capsys)
    assert code == 1
    if taken == "folder":
        assert f"{src / name} already exists; choose another name or remove it" in out
    else:
        assert f"a package named {name!r} already exists (" in out and "choose another name" in out
    assert listing(workspace_root) == before
