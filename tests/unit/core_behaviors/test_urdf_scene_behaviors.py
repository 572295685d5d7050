"""AddURDF, AttachURDF, DetachURDF, RemoveURDFFromScene, IsAnyObjectAttached, WhichObjectIsAttached and
SetupMTCSetCollisionRule on lab_sim's model: a URDF tool in the planning scene is what the planner checks."""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import publish_repeatedly, tick_behavior
from kinema.transport import from_dict

ARM = [
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
]
HOME = [0.0, 0.0, -2.0, 2.0, -1.5708, -1.5708, 0.0]
# grasp_link 0.30 m above the table's top, pointing down
OVER_TABLE = [-0.1333, 0.0, -1.25758, 1.37827, -1.69149, -1.5708, 0.0]

ROD_TOOL = """<?xml version="1.0"?>
<robot name="rod_tool">
  <link name="tool_base">
    <collision><origin xyz="0 0 0.22"/><geometry><box size="0.04 0.04 0.40"/></geometry></collision>
  </link>
  <link name="finger"/>
  <joint name="finger_joint" type="prismatic">
    <parent link="tool_base"/><child link="finger"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.04" effort="1" velocity="1"/>
  </joint>
</robot>
"""


@pytest.fixture
def cell(node: Any, lab_sim_model: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    """lab_sim's model and scene (table, tray, ...), no config: files resolve in ``tmp_path``; the arm at
    HOME until the test moves it (``cell.move_to(arm)``)."""
    from kinema.motion import RobotDescription

    monkeypatch.chdir(tmp_path)
    (tmp_path / "rod_tool.urdf").write_text(ROD_TOOL)
    scene = RobotDescription.lab_sim().load_scene(lab_sim_model)
    context = BehaviorContext(node, robot_model=lab_sim_model, planning_scene=scene)

    class Cell:
        def __init__(self) -> None:
            self.context = context
            self.scene = scene
            self._publishing: Any = None

        def move_to(self, arm: list[float]) -> None:
            if self._publishing is not None:
                self._publishing.__exit__(None, None, None)
            state = {"name": [*ARM, "robotiq_85_left_knuckle_joint"], "position": [*arm, 0.0]}
            self._publishing = publish_repeatedly(node, "sensor_msgs/msg/JointState", "/joint_states", state)
            self._publishing.__enter__()
            deadline = time.monotonic() + 10.0
            while not np.allclose(context.joint_states.fresh(5.0).position[: len(arm)], arm):
                assert time.monotonic() < deadline, "the joint state never showed the new arm position"

    cell = Cell()
    cell.move_to(HOME)
    try:
        yield cell
    finally:
        cell._publishing.__exit__(None, None, None)
        context.close()


def _grasp_pose() -> Any:
    return from_dict(
        "geometry_msgs/msg/PoseStamped",
        {"header": {"frame_id": "grasp_link"}, "pose": {"orientation": {"w": 1}}},
    )


def _trajectory(*arms: list[float]) -> Any:
    return from_dict(
        "trajectory_msgs/msg/JointTrajectory",
        {
            "joint_names": ARM,
            "points": [{"positions": arm, "time_from_start": {"sec": k}} for k, arm in enumerate(arms)],
        },
    )


def _add_rod(behavior: Any, cell: Any) -> Any:
    return tick_behavior(
        behavior("AddURDF"),
        {"urdf_name": "rod", "urdf_file_path": "rod_tool.urdf", "urdf_pose": _grasp_pose()},
        context=cell.context,
    )


def test_a_carried_urdf_tool_is_checked_by_the_planner_and_left_where_it_is_detached(
    behavior: Any, cell: Any, lab_sim_model: Any
) -> None:
    from kinema.motion import fk

    added = _add_rod(behavior, cell)
    assert added.status == NodeStatus.SUCCESS, added.toasts
    assert "finger_joint are held at 0" in added.toasts[-1]
    home_grasp = fk(
        lab_sim_model, lab_sim_model.configuration(dict(zip(ARM, HOME, strict=True))), "grasp_link"
    )
    np.testing.assert_allclose(cell.scene.world_poses["rod"], home_grasp, atol=1e-6)
    validate = behavior("ValidateTrajectory")
    sweep = {"joint_trajectory_msg": _trajectory(HOME, OVER_TABLE), "planning_group_name": "manipulator"}
    # left in the world beside the table, the rod is not in the arm's way
    assert tick_behavior(validate, sweep, context=cell.context).status == NodeStatus.SUCCESS

    attached = tick_behavior(
        behavior("AttachURDF"), {"urdf_name": "rod", "parent_link_name": "grasp_link"}, context=cell.context
    )
    assert attached.status == NodeStatus.SUCCESS, attached.toasts
    carried = tick_behavior(validate, sweep, context=cell.context)
    assert carried.status == NodeStatus.FAILURE
    assert "rod - table" in carried.toasts[-1]

    cell.move_to(OVER_TABLE)
    over_grasp = fk(
        lab_sim_model, lab_sim_model.configuration(dict(zip(ARM, OVER_TABLE, strict=True))), "grasp_link"
    )
    # the carried object is a frame of the cell that moves with its link
    in_rod = from_dict("geometry_msgs/msg/PoseStamped", {"header": {"frame_id": "rod"}, "pose": {}})
    seen = tick_behavior(
        behavior("TransformPoseFrame"),
        {"input_pose": in_rod, "target_frame_id": "world"},
        context=cell.context,
    )
    position = seen.outputs["output_pose"].pose.position
    np.testing.assert_allclose([position.x, position.y, position.z], over_grasp[:3, 3], atol=1e-6)
    detached = tick_behavior(behavior("DetachURDF"), {"urdf_name": "rod"}, context=cell.context)
    assert detached.status == NodeStatus.SUCCESS, detached.toasts
    np.testing.assert_allclose(cell.scene.world_poses["rod"], over_grasp, atol=1e-6)
    removed = tick_behavior(behavior("RemoveURDFFromScene"), {"urdf_name": "rod"}, context=cell.context)
    assert removed.status == NodeStatus.SUCCESS and "rod" not in cell.scene.world


def test_what_is_attached_is_read_from_the_current_planning_scene(behavior: Any, cell: Any) -> None:
    def scene() -> Any:
        run = tick_behavior(behavior("GetCurrentPlanningScene"), context=cell.context)
        return run.outputs["planning_scene_msg"]

    assert _add_rod(behavior, cell).status == NodeStatus.SUCCESS
    empty = tick_behavior(behavior("IsAnyObjectAttached"), {"planning_scene": scene()}, context=cell.context)
    assert empty.status == NodeStatus.FAILURE and "no object is attached" in empty.toasts[-1]
    tick_behavior(
        behavior("AttachURDF"), {"urdf_name": "rod", "parent_link_name": "tool0"}, context=cell.context
    )
    message = scene()
    assert (
        tick_behavior(
            behavior("IsAnyObjectAttached"), {"planning_scene": message}, context=cell.context
        ).status
        == NodeStatus.SUCCESS
    )
    which = tick_behavior(
        behavior("WhichObjectIsAttached"),
        {"planning_scene": message, "object_names": ["inspector", "rod"]},
        context=cell.context,
    )
    assert which.status == NodeStatus.SUCCESS and which.outputs["object_name"] == "rod"
    none = tick_behavior(
        behavior("WhichObjectIsAttached"),
        {"planning_scene": message, "object_names": ["inspector"]},
        context=cell.context,
    )
    assert none.status == NodeStatus.FAILURE and "attached: rod" in none.toasts[-1]


@pytest.mark.parametrize(
    ("behavior_id", "inputs", "message"),
    [
        ("AttachURDF", {"urdf_name": "rdo", "parent_link_name": "tool0"}, "no URDF object 'rdo'"),
        ("AttachURDF", {"urdf_name": "rod", "parent_link_name": "tool9"}, "'tool9' is no link of the robot"),
        (
            "AttachURDF",
            {"urdf_name": "rod", "parent_link_name": "tool0", "allowed_collision_links": ["link_5"]},
            "names 'link_5', which is no link of the robot",
        ),
        ("AttachURDF", {"urdf_name": "rod"}, "robot.tool_frame"),
        ("DetachURDF", {"urdf_name": "rod"}, "no URDF object 'rod' is attached"),
        ("RemoveURDFFromScene", {"urdf_name": "box"}, "no URDF object 'box'"),
    ],
)
def test_urdf_behaviors_fail_naming_what_is_wrong(
    behavior: Any, cell: Any, behavior_id: str, inputs: dict[str, Any], message: str
) -> None:
    assert _add_rod(behavior, cell).status == NodeStatus.SUCCESS
    cell.scene.add_box("box", (0.1, 0.1, 0.1), np.eye(4))
    run = tick_behavior(behavior(behavior_id), inputs, context=cell.context)
    assert run.status == NodeStatus.FAILURE
    assert message in run.toasts[-1]


def test_an_attached_urdf_must_be_detached_before_it_is_removed(behavior: Any, cell: Any) -> None:
    assert _add_rod(behavior, cell).status == NodeStatus.SUCCESS
    tick_behavior(
        behavior("AttachURDF"), {"urdf_name": "rod", "parent_link_name": "tool0"}, context=cell.context
    )
    run = tick_behavior(behavior("RemoveURDFFromScene"), {"urdf_name": "rod"}, context=cell.context)
    assert run.status == NodeStatus.FAILURE and "DetachURDF it first" in run.toasts[-1]
    assert "rod" in cell.scene.attached


def test_add_urdf_names_a_missing_file_and_a_urdf_without_collision_geometry(
    behavior: Any, cell: Any, tmp_path: Path
) -> None:
    missing = tick_behavior(
        behavior("AddURDF"),
        {"urdf_name": "t", "urdf_file_path": "nothing.urdf", "urdf_pose": _grasp_pose()},
        context=cell.context,
    )
    assert missing.status == NodeStatus.FAILURE and "'nothing.urdf': no such file" in missing.toasts[-1]
    (tmp_path / "empty.urdf").write_text("<robot name='e'><link name='a'/></robot>")
    empty = tick_behavior(
        behavior("AddURDF"),
        {"urdf_name": "t", "urdf_file_path": "empty.urdf", "urdf_pose": _grasp_pose()},
        context=cell.context,
    )
    assert empty.status == NodeStatus.FAILURE and "no <collision> geometry" in empty.toasts[-1]


def test_set_collision_rule_lets_a_task_plan_through_an_object_and_forbids_it_again(
    behavior: Any, cell: Any
) -> None:
    from kinema.motion.task_stages import AllowCollisions

    task = tick_behavior(behavior("InitializeMTCTask"), {"task_id": "t"}, context=cell.context).outputs[
        "task"
    ]
    for allow in (True, False):
        run = tick_behavior(
            behavior("SetupMTCSetCollisionRule"),
            {"task": task, "name_a": "gripper", "name_b": "rod;<octomap>", "allow_collision": allow},
            context=cell.context,
        )
        assert run.status == NodeStatus.SUCCESS, run.toasts
        task = run.outputs["task"]
    allow_stage, forbid_stage = task.stages
    assert isinstance(allow_stage, AllowCollisions) and allow_stage.allow
    assert list(allow_stage.second) == ["rod", "<octomap>"] and not forbid_stage.allow
    empty = tick_behavior(
        behavior("SetupMTCSetCollisionRule"), {"task": task, "name_a": "gripper"}, context=cell.context
    )
    assert empty.status == NodeStatus.FAILURE and "port [name_b] is empty" in empty.toasts[-1]


@pytest.mark.parametrize("allow", [False, True])
def test_a_task_reaches_a_goal_where_the_carried_tool_touches_the_table_only_when_allowed(
    behavior: Any, cell: Any, allow: bool
) -> None:
    assert _add_rod(behavior, cell).status == NodeStatus.SUCCESS
    tick_behavior(
        behavior("AttachURDF"), {"urdf_name": "rod", "parent_link_name": "grasp_link"}, context=cell.context
    )
    task = tick_behavior(behavior("InitializeMTCTask"), {"task_id": "t"}, context=cell.context).outputs[
        "task"
    ]
    task = tick_behavior(behavior("SetupMTCCurrentState"), {"task": task}, context=cell.context).outputs[
        "task"
    ]
    if allow:
        task = tick_behavior(
            behavior("SetupMTCSetCollisionRule"),
            {"task": task, "name_a": "rod", "name_b": "table"},
            context=cell.context,
        ).outputs["task"]
    goal = from_dict("sensor_msgs/msg/JointState", {"name": ARM, "position": OVER_TABLE})
    task = tick_behavior(
        behavior("SetupMTCPlanToRobotState"),
        {"task": task, "joint_state": goal, "planning_group_name": "manipulator"},
        context=cell.context,
    ).outputs["task"]
    run = tick_behavior(behavior("PlanMTCTask"), {"task": task}, context=cell.context, timeout=60)
    if allow:
        assert run.status == NodeStatus.SUCCESS, run.toasts
        assert [s.stage for s in run.outputs["solution"].sub_trajectories] == ["plan to joint state"]
    else:
        assert run.status == NodeStatus.FAILURE
        assert "rod" in run.toasts[-1] and "table" in run.toasts[-1]
