"""``kinema new config`` on robots of example-robot-data that new users brought: the xArm7 (an SRDF group of
joints ending with the fixed ``joint_eef``, and a group state ``home``), the SO-101 (no SRDF; its tool point
``gripper_frame_link`` is fixed beyond the chain's tip) and the Kinova (an SRDF state outside its limits)."""

from __future__ import annotations

import math
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


def test_an_srdf_state_outside_the_limits_is_clipped_as_the_scene_is_and_said(
    robots: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """The Kinova's SRDF state arm_up has joint_3 = -1.5707, outside the URDF's [0.33, 5.95]: MuJoCo clips
    the scene's keyframe, so the waypoint says the same place (it said -1.5707 and only failed when run)."""
    folder = robots / "kinova_description"
    plan = plan_robot(
        "kinova_cell",
        folder / "robots" / "kinova.urdf",
        srdf=folder / "srdf" / "kinova.srdf",
        xacro_args=None,
        index=PackageIndex(environ={}),
    )
    assert plan.waypoints["arm_up"]["j2s6s200_joint_3"] == pytest.approx(0.331613, abs=1e-6)
    # The SRDF's own notes are said once, at the user's file (not again at a temporary copy's).
    assert sum("names no group" in note for note in plan.notes) == 1
    assert not [r.getMessage() for r in caplog.records if "names no group" in r.getMessage()]
    assert any(
        note.startswith("waypoint 'arm_up': the SRDF gives j2s6s200_joint_3 = -1.5707, outside its limits")
        for note in plan.notes
    ), plan.notes


def test_a_hand_whose_finger_joints_are_fixed_is_said_to_be_no_gripper(robots: Path) -> None:
    plan = plan_robot(
        "kinova_cell",
        robots / "kinova_description" / "robots" / "kinova.urdf",
        srdf=None,
        xacro_args=None,
        index=PackageIndex(environ={}),
    )
    assert plan.gripper_joint is None
    assert any(note.startswith("no gripper: the URDF's j2s6s200_joint_finger_1") for note in plan.notes), (
        plan.notes
    )
    # Its continuous wrists plan within two turns (the package did not build before).
    assert plan.waypoints["Home"]["j2s6s200_joint_1"] == 0.0
    # Its shoulder and elbow exclude 0: its rest pose has them mid-range, not against the stop the arm
    # folded into the table at (and through itself). Mid-range it stands straight up, singular: Home bends
    # the shoulder 45° from there (kinema.scaffold.home_pose).
    assert plan.home["j2s6s200_joint_2"] == pytest.approx((0.820305 + 5.462881) / 2 - math.pi / 4, abs=1e-3)
    assert plan.home_note is not None and "near-singular" in plan.home_note
    assert not any(
        "in collision at Home" in note or "Home is in self-collision" in note for note in plan.notes
    )
