"""``kinema new config``'s tool frame and waypoints on robots of example-robot-data two new users brought:
the xArm7 (an SRDF group of joints ending with the fixed ``joint_eef``, and a group state ``home``) and the
SO-101 (no SRDF; its tool point ``gripper_frame_link`` is fixed beyond the chain's tip)."""

from __future__ import annotations

from pathlib import Path

import pytest

from kinema.config.robot_files import PackageIndex
from kinema.scaffold.robot_package import plan_robot


@pytest.fixture(scope="module")
def robots() -> Path:
    share = PackageIndex(environ={}).find("example-robot-data")
    if share is None:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data, in the test extra)")
    return share / "robots"


def test_an_srdf_group_of_joints_ends_at_its_fixed_last_joint_and_home_is_one_waypoint(robots: Path) -> None:
    folder = robots / "xarm_description"
    plan = plan_robot(
        "xarm_cell",
        folder / "urdf" / "xarm7.urdf",
        srdf=folder / "srdf" / "xarm7.srdf",
        xacro_args=None,
        index=PackageIndex(environ={}),
    )
    assert plan.tool_frame == "link_eef"  # the group's joint_eef leads there (link7 was chosen before)
    # The SRDF's "home" is Home: not a second waypoint "home" beside it.
    assert list(plan.waypoints) == ["Home", "hold-up"]


def test_a_tool_point_fixed_beyond_the_chain_is_the_tool_frame(robots: Path) -> None:
    plan = plan_robot(
        "so_cell",
        robots / "so_arm_description" / "urdf" / "so101.urdf",
        srdf=None,
        xacro_args=None,
        index=PackageIndex(environ={}),
    )
    assert plan.tool_frame == "gripper_frame_link"  # the point between the jaws, 10 cm beyond gripper_link
    assert any("tool frame 'gripper_frame_link'" in note for note in plan.notes), plan.notes
    ur5 = plan_robot(
        "ur5_cell",
        robots / "ur_description" / "urdf" / "ur5_robot.urdf",
        srdf=None,
        xacro_args=None,
        index=PackageIndex(environ={}),
    )
    assert ur5.tool_frame == "ee_link"  # unchanged: its chain already ends there
