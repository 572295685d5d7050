from __future__ import annotations

import numpy as np
import pytest

from kinema.errors import MotionError
from kinema.motion import RobotModel, fk
from kinema.motion.joint_limits import parse_joint_limits
from kinema.motion.srdf import parse_srdf

ARM = (
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)


def test_joints_are_moveit_pro_names_and_mimic_fingers_are_not_coordinates(model):
    assert model.joint_names == (*ARM, "robotiq_85_left_knuckle_joint")
    assert set(model.mimics) == {"robotiq_85_left_finger_joint", "robotiq_85_right_finger_joint"}


@pytest.mark.parametrize(
    ("group", "joints", "tip"),
    [
        ("manipulator", ARM, "grasp_link"),
        ("gripper", ("robotiq_85_left_knuckle_joint",), None),
        ("linear_actuator", ("linear_rail_joint",), None),
    ],
)
def test_srdf_groups_resolve_to_joints(model, group, joints, tip):
    g = model.group(group)
    assert g.joint_names == joints
    assert g.tip_link == tip
    assert [model.joint_names[i] for i in g.indices] == list(joints)


def test_limits_combine_urdf_positions_and_yaml_velocities(model):
    rail = model.limits["linear_rail_joint"]
    assert (rail.lower, rail.upper) == (-1.2, 1.2)
    assert rail.max_velocity == 0.8 and rail.max_acceleration == 2.0
    assert model.limits["robotiq_85_left_knuckle_joint"].upper == pytest.approx(0.7929)
    assert np.all(np.isfinite(model.max_acceleration))


def test_unknown_names_list_the_valid_ones(model):
    with pytest.raises(MotionError, match=r"unknown planning group 'manipulater'.*manipulator"):
        model.group("manipulater")
    with pytest.raises(MotionError, match=r"unknown joint 'elbow'.*elbow_joint"):
        model.configuration({"elbow": 1.0})
    with pytest.raises(MotionError, match=r"unknown frame 'tool'.*tool0"):
        fk(model, model.neutral(), "tool")


def test_fingers_follow_the_knuckle(model):
    q_open = model.configuration({"robotiq_85_left_knuckle_joint": 0.0})
    q_closed = model.configuration({"robotiq_85_left_knuckle_joint": 0.7929})
    gap = {}
    for label, q in (("open", q_open), ("closed", q_closed)):
        left = fk(model, q, "robotiq_85_left_finger_link")[:3, 3]
        right = fk(model, q, "robotiq_85_right_finger_link")[:3, 3]
        gap[label] = float(np.linalg.norm(left - right)) - 2 * 0.01  # minus the two pad half-thicknesses
    assert gap["open"] == pytest.approx(0.085, abs=1e-6)
    assert gap["closed"] == pytest.approx(0.0, abs=1e-6)


def test_named_states_from_the_srdf(model):
    q = model.named_state("gripper", "close")
    assert q[model.index("robotiq_85_left_knuckle_joint")] == pytest.approx(0.7929)
    with pytest.raises(MotionError, match=r"no named state 'shut'.*close"):
        model.named_state("gripper", "shut")


def test_srdf_elements_missing_an_attribute_are_skipped_with_a_note_at_their_line(tmp_path):
    # As MoveIt's SRDF reader skips them (logging an error): a file MoveIt loads, Kinema loads.
    bad = tmp_path / "bad.srdf"
    bad.write_text(
        '<robot name="r">\n  <group name="arm">\n    <chain base_link="a"/>\n    <joint name="j1"/>\n'
        '  </group>\n  <group_state name="home">\n    <joint name="j1" value="0.5"/>\n  </group_state>\n'
        '  <disable_collisions link1="a"/>\n</robot>\n'
    )
    semantic = parse_srdf(bad)
    assert semantic.groups["arm"].chains == () and semantic.groups["arm"].joints == ("j1",)
    # A state without its group keeps its values (pinocchio reads them so; example-robot-data writes them so).
    assert semantic.group_states[("", "home")] == {"j1": 0.5}
    assert semantic.disabled_collisions == frozenset()
    assert semantic.notes == (
        f"{bad}:3: <chain> has no 'tip_link' attribute; skipped, as MoveIt skips it",
        f"{bad}:6: <group_state name='home'> names no group; its joint values are kept (MoveIt skips such a "
        "state)",
        f"{bad}:9: <disable_collisions> has no 'link2' attribute; skipped, as MoveIt skips it",
    )


def test_a_group_state_value_that_is_no_number_is_an_error_at_its_line(tmp_path):
    bad = tmp_path / "bad.srdf"
    bad.write_text(
        '<robot name="r">\n  <group_state name="home" group="arm">\n    <joint name="j1" value="up"/>\n'
        "  </group_state>\n</robot>\n"
    )
    with pytest.raises(MotionError, match=r"joint 'j1' has the value 'up', not a number") as info:
        parse_srdf(bad)
    assert str(info.value).startswith(f"{bad}:3:")


def test_joint_limits_errors_name_the_joint(tmp_path):
    bad = tmp_path / "joint_limits.yaml"
    bad.write_text("joint_limits:\n  elbow_joint:\n    has_velocity_limits: true\n    max_velocity: fast\n")
    with pytest.raises(MotionError, match=r"elbow_joint.max_velocity must be a number"):
        parse_joint_limits(bad)


def test_group_with_unknown_joint_is_rejected(tmp_path, description):
    srdf = tmp_path / "r.srdf"
    srdf.write_text('<robot name="r"><group name="arm"><joint name="elbo_joint"/></group></robot>')
    with pytest.raises(MotionError, match=r"unknown joint 'elbo_joint'.*elbow_joint"):
        RobotModel.from_urdf(description.urdf, srdf)


def _two_link_urdf(path, *, joint_type: str, fixed_named_like_link: bool = False):
    """A base, one arm link on a joint of ``joint_type``, and a tool link on a fixed joint (named like the
    tool link with ``fixed_named_like_link``, as the Unitree Z1's gripperStator)."""
    tool_joint = "tool" if fixed_named_like_link else "tool_joint"
    limit = (
        '<limit effort="5" velocity="2"/>'
        if joint_type == "continuous"
        else ('<limit lower="-1" upper="1" effort="5" velocity="2"/>')
    )
    path.write_text(
        f"""<?xml version="1.0"?>
<robot name="twolink">
  <link name="base"/><link name="arm"/><link name="tool"/>
  <joint name="turn" type="{joint_type}"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>{limit}</joint>
  <joint name="{tool_joint}" type="fixed"><parent link="arm"/><child link="tool"/>
    <origin xyz="0.2 0 0"/></joint>
</robot>
"""
    )
    return path


def test_a_continuous_joint_plans_as_a_revolute_one_within_two_turns(tmp_path):
    """Kinova's (and many arms') wrists are continuous in their URDF: the model loads them with one
    coordinate and limits of two turns either way, its effort and velocity kept."""
    import math

    from kinema.motion import RobotModel, fk

    model = RobotModel.from_urdf(_two_link_urdf(tmp_path / "twolink.urdf", joint_type="continuous"))
    assert model.joint_names == ("turn",)
    limits = model.limits["turn"]
    assert (limits.lower, limits.upper) == pytest.approx((-2 * math.pi, 2 * math.pi))
    assert limits.max_velocity == pytest.approx(2.0)
    tool = fk(model, model.configuration({"turn": math.pi / 2}), "tool")[:3, 3]
    assert tool == pytest.approx([0.0, 0.2, 0.1], abs=1e-9)


def test_a_fixed_joint_named_like_its_link_leaves_the_link_reachable_by_name(tmp_path):
    """pinocchio makes two frames of that name and refuses the name alone; the link is the one meant."""
    from kinema.motion import RobotModel, fk

    path = _two_link_urdf(tmp_path / "twolink.urdf", joint_type="revolute", fixed_named_like_link=True)
    model = RobotModel.from_urdf(path)
    assert fk(model, model.configuration({"turn": 0.0}), "tool")[:3, 3] == pytest.approx([0.2, 0.0, 0.1])
