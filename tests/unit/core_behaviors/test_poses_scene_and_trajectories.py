"""Pose maths and frames, the planning scene behaviors, trajectory utilities and bad input (lab_sim model)."""

from __future__ import annotations

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
GRIPPER = "robotiq_85_left_knuckle_joint"
HOME = [0.0, 0.0, -2.0, 2.0, -1.5708, -1.5708, 0.0]
MID = [-0.1333, 0.0, -1.25758, 1.37827, -1.69149, -1.5708, 0.0]


@pytest.fixture
def at_home(context: BehaviorContext) -> Any:
    state = {"name": [*ARM, GRIPPER], "position": [*HOME, 0.0]}
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        yield


def _q(model: Any, arm: list[float]) -> np.ndarray:
    q = np.zeros(len(model.joint_names))
    q[[model.joint_names.index(n) for n in ARM]] = arm
    return q


def _pose(frame: str, xyz: tuple[float, float, float], xyzw: tuple[float, ...] = (0, 0, 0, 1)) -> Any:
    x, y, z = xyz
    qx, qy, qz, qw = xyzw
    return from_dict(
        "geometry_msgs/msg/PoseStamped",
        {
            "header": {"frame_id": frame},
            "pose": {
                "position": {"x": x, "y": y, "z": z},
                "orientation": {"x": qx, "y": qy, "z": qz, "w": qw},
            },
        },
    )


def _xyz(pose: Any) -> np.ndarray:
    p = pose.pose.position
    return np.array([p.x, p.y, p.z])


def _joint_state(arm: list[float]) -> Any:
    return from_dict("sensor_msgs/msg/JointState", {"name": ARM, "position": arm})


# -- poses and frames ------------------------------------------------------------------------------


def test_transform_pose_frame_puts_the_grasp_link_in_the_world(
    behavior: Any, context: BehaviorContext, at_home: Any, lab_sim_model: Any
) -> None:
    from kinema.motion import fk

    run = tick_behavior(
        behavior("TransformPoseFrame"),
        {"input_pose": _pose("grasp_link", (0, 0, 0)), "target_frame_id": "world"},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    expected = fk(lab_sim_model, _q(lab_sim_model, HOME), "grasp_link")[:3, 3]
    assert run.outputs["output_pose"].header.frame_id == "world"
    np.testing.assert_allclose(_xyz(run.outputs["output_pose"]), expected, atol=1e-6)
    back = tick_behavior(
        behavior("TransformPoseFrame"),
        {"input_pose": run.outputs["output_pose"], "target_frame_id": "grasp_link"},
        context=context,
    )
    np.testing.assert_allclose(_xyz(back.outputs["output_pose"]), [0, 0, 0], atol=1e-6)


def test_transform_pose_frame_to_a_frame_that_does_not_exist_names_the_close_ones(
    behavior: Any, context: BehaviorContext, at_home: Any
) -> None:
    run = tick_behavior(
        behavior("TransformPoseFrame"),
        {"input_pose": _pose("world", (1, 0, 0)), "target_frame_id": "grasp_lnk"},
        context=context,
    )
    assert run.status == NodeStatus.FAILURE
    assert "'grasp_lnk'" in run.toasts[-1] and "grasp_link" in run.toasts[-1]


def test_calculate_pose_offset_and_transform_pose_with_pose_undo_each_other(
    behavior: Any, context: BehaviorContext
) -> None:
    tag = _pose("world", (0.6, 0.2, 0.8), (0, 0, 0.7071068, 0.7071068))
    gripper = _pose("world", (0.65, 0.25, 0.9), (1, 0, 0, 0))
    offset = tick_behavior(
        behavior("CalculatePoseOffset"), {"source_pose": tag, "destination_pose": gripper}, context=context
    )
    assert offset.status == NodeStatus.SUCCESS, offset.toasts
    relative = offset.outputs["source_to_destination_pose"]
    # 5 cm along world x is 5 cm along the tag's -y (the tag is turned 90 degrees about z)
    np.testing.assert_allclose(_xyz(relative), [0.05, -0.05, 0.1], atol=1e-6)
    again = tick_behavior(
        behavior("TransformPoseWithPose"), {"input_pose": relative, "transform_pose": tag}, context=context
    )
    assert again.status == NodeStatus.SUCCESS, again.toasts
    np.testing.assert_allclose(_xyz(again.outputs["output_pose"]), [0.65, 0.25, 0.9], atol=1e-6)
    o = again.outputs["output_pose"].pose.orientation
    assert abs(abs(o.x) - 1.0) < 1e-6


def test_compute_link_pose_forward_kinematics_for_a_given_state(
    behavior: Any, context: BehaviorContext, at_home: Any, lab_sim_model: Any
) -> None:
    from kinema.motion import fk

    run = tick_behavior(
        behavior("ComputeLinkPoseForwardKinematics"),
        {"joint_state": _joint_state(MID), "link_name": "grasp_link"},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    expected = fk(lab_sim_model, _q(lab_sim_model, MID), "grasp_link")[:3, 3]
    np.testing.assert_allclose(_xyz(run.outputs["link_pose"]), expected, atol=1e-6)
    bad = tick_behavior(
        behavior("ComputeLinkPoseForwardKinematics"),
        {"joint_state": _joint_state(MID), "link_name": "gripper_link"},
        context=context,
    )
    assert bad.status == NodeStatus.FAILURE and "'gripper_link'" in bad.toasts[-1]


def test_a_port_of_the_wrong_type_fails_naming_port_value_and_alternative(
    behavior: Any, context: BehaviorContext
) -> None:
    run = tick_behavior(
        behavior("TransformPoseWithPose"),
        {"input_pose": "0.1;0.2;0.3", "transform_pose": _pose("world", (0, 0, 0))},
        context=context,
    )
    assert run.status == NodeStatus.FAILURE
    assert "[input_pose]" in run.toasts[-1] and "PoseStamped" in run.toasts[-1]


# -- the planning scene ----------------------------------------------------------------------------


def _scene_ids(behavior: Any, context: BehaviorContext) -> tuple[list[str], Any]:
    run = tick_behavior(behavior("GetCurrentPlanningScene"), context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    scene = run.outputs["planning_scene_msg"]
    return [str(o.id) for o in scene.world.collision_objects], scene


def test_a_box_in_front_of_the_gripper_is_in_the_scene_until_reset(
    behavior: Any, context: BehaviorContext, at_home: Any, lab_sim_model: Any
) -> None:
    from kinema.motion import fk

    add = tick_behavior(
        behavior("AddCollisionBox"),
        {"object_id": "in_front", "dimensions": "0.3;0.3;0.3", "pose": _pose("grasp_link", (0, 0, 0.1))},
        context=context,
    )
    assert add.status == NodeStatus.SUCCESS, add.toasts
    ids, scene = _scene_ids(behavior, context)
    assert ids == ["in_front"]
    box = scene.world.collision_objects[0]
    assert list(box.primitives[0].dimensions) == pytest.approx([0.3, 0.3, 0.3])
    expected = fk(lab_sim_model, _q(lab_sim_model, HOME), "grasp_link") @ np.array([0, 0, 0.1, 1.0])
    placed = box.primitive_poses[0].position
    np.testing.assert_allclose([placed.x, placed.y, placed.z], expected[:3], atol=1e-6)
    found = tick_behavior(
        behavior("IsCollisionObjectInPlanningScene"),
        {"planning_scene": scene, "collision_object_name": "in_front"},
        context=context,
    )
    assert found.status == NodeStatus.SUCCESS
    missing = tick_behavior(
        behavior("IsCollisionObjectInPlanningScene"),
        {"planning_scene": scene, "collision_object_name": "table"},
        context=context,
    )
    assert missing.status == NodeStatus.FAILURE and "'in_front'" in missing.toasts[-1]
    again = tick_behavior(
        behavior("AddCollisionBox"),
        {"object_id": "in_front", "pose": _pose("world", (1, 1, 1)), "overwrite": False},
        context=context,
    )
    assert again.status == NodeStatus.FAILURE and "already in the planning scene" in again.toasts[-1]
    assert tick_behavior(behavior("ResetPlanningSceneObjects"), context=context).status == NodeStatus.SUCCESS
    assert _scene_ids(behavior, context)[0] == []


@pytest.mark.parametrize(
    ("inputs", "expected"),
    [
        ({"object_id": "", "pose": None}, "port [object_id] is empty"),
        ({"dimensions": "0.1;0.1", "pose": None}, "port [dimensions] has 2 values"),
        ({"dimensions": "0.1;0;0.1", "pose": None}, "each size must be > 0 m"),
        ({"pose": "not a pose"}, "port [pose]"),
        ({"pose": _pose("no_such_frame", (0, 0, 0))}, "unknown frame 'no_such_frame'"),
    ],
)
def test_add_collision_box_bad_input(
    behavior: Any, context: BehaviorContext, at_home: Any, inputs: dict, expected: str
) -> None:
    values = {"object_id": "b", "dimensions": "0.1;0.1;0.1", **inputs}
    if values.get("pose") is None:
        values["pose"] = _pose("world", (1, 0, 1))
    run = tick_behavior(behavior("AddCollisionBox"), values, context=context)
    assert run.status == NodeStatus.FAILURE
    assert expected in run.toasts[-1], run.toasts


def _collision_object(shape_type: int, dimensions: list[float], operation: int = 0) -> Any:
    return from_dict(
        "moveit_msgs/msg/CollisionObject",
        {
            "id": "thing",
            "header": {"frame_id": "world"},
            "pose": {"position": {"x": 0.7, "y": 0.0, "z": 1.0}, "orientation": {"w": 1.0}},
            "primitives": [{"type": shape_type, "dimensions": dimensions}],
            "primitive_poses": [{"orientation": {"w": 1.0}}],
            "operation": operation,
        },
    )


def test_add_collision_object_adds_and_removes_and_refuses_cones(
    behavior: Any, context: BehaviorContext, at_home: Any
) -> None:
    add = tick_behavior(
        behavior("AddCollisionObject"),
        {"collision_object": _collision_object(3, [0.2, 0.05])},
        context=context,
    )
    assert add.status == NodeStatus.SUCCESS, add.toasts
    ids, scene = _scene_ids(behavior, context)
    assert ids == ["thing"] and list(scene.world.collision_objects[0].primitives[0].dimensions) == [0.2, 0.05]
    remove = tick_behavior(
        behavior("AddCollisionObject"),
        {"collision_object": _collision_object(3, [0.2, 0.05], 1)},
        context=context,
    )
    assert remove.status == NodeStatus.SUCCESS and _scene_ids(behavior, context)[0] == []
    cone = tick_behavior(
        behavior("AddCollisionObject"),
        {"collision_object": _collision_object(4, [0.2, 0.05])},
        context=context,
    )
    assert cone.status == NodeStatus.FAILURE and "CONE" in cone.toasts[-1] and "BOX (1)" in cone.toasts[-1]


def _object_message(object_id: str, operation: int, xyz: tuple[float, float, float], **extra: Any) -> Any:
    return from_dict(
        "moveit_msgs/msg/CollisionObject",
        {
            "id": object_id,
            "header": {"frame_id": "world"},
            "pose": {
                "position": dict(zip("xyz", xyz, strict=True)),
                "orientation": extra.pop("q", {"w": 1.0}),
            },
            "operation": operation,
            **extra,
        },
    )


def _centres(behavior: Any, context: BehaviorContext, object_id: str) -> list[float]:
    """The centres of the object's primitives, flattened (x, y, z, x, y, z, ...), in the world."""
    _, scene = _scene_ids(behavior, context)
    (obj,) = [o for o in scene.world.collision_objects if o.id == object_id]
    return [v for p in obj.primitive_poses for v in (p.position.x, p.position.y, p.position.z)]


def test_add_collision_object_appends_and_moves_as_moveit_does(
    behavior: Any, context: BehaviorContext, at_home: Any
) -> None:
    def apply(message: Any) -> Any:
        return tick_behavior(behavior("AddCollisionObject"), {"collision_object": message}, context=context)

    cylinder = {"primitives": [{"type": 3, "dimensions": [0.2, 0.05]}], "primitive_poses": [{}]}
    assert apply(_object_message("rack", 0, (0.7, 0.0, 1.0), **cylinder)).status == NodeStatus.SUCCESS
    # APPEND: a box 10 cm along the object's x joins the cylinder; the object is now both.
    box = {
        "primitives": [{"type": 1, "dimensions": [0.05, 0.05, 0.05]}],
        "primitive_poses": [{"position": {"x": 0.1}}],
    }
    appended = apply(_object_message("rack", 2, (0.7, 0.0, 1.0), **box))
    assert appended.status == NodeStatus.SUCCESS, appended.toasts
    assert _centres(behavior, context, "rack") == pytest.approx([0.7, 0.0, 1.0, 0.8, 0.0, 1.0])
    # MOVE: the whole object goes to the new pose, a quarter turn about z: the box swings round with it.
    quarter = {"z": 0.7071068, "w": 0.7071068}
    moved = apply(_object_message("rack", 3, (0.2, 0.5, 0.9), q=quarter))
    assert moved.status == NodeStatus.SUCCESS, moved.toasts
    assert _centres(behavior, context, "rack") == pytest.approx([0.2, 0.5, 0.9, 0.2, 0.6, 0.9], abs=1e-6)
    # APPEND to an id nobody added creates it, as in MoveIt.
    assert apply(_object_message("new", 2, (0.5, 0.5, 1.0), **box)).status == NodeStatus.SUCCESS
    assert _centres(behavior, context, "new") == pytest.approx([0.6, 0.5, 1.0])
    # MOVE of an unknown id, and an unknown operation, fail with what there is.
    lost = apply(_object_message("missing", 3, (0.0, 0.0, 1.0)))
    assert lost.status == NodeStatus.FAILURE and "'missing'" in lost.toasts[-1], lost.toasts
    assert "rack" in lost.toasts[-1] or "new" in lost.toasts[-1], lost.toasts
    odd = apply(_object_message("rack", 7, (0.0, 0.0, 1.0)))
    assert odd.status == NodeStatus.FAILURE and "APPEND (2), MOVE (3)" in odd.toasts[-1], odd.toasts
    for object_id in ("rack", "new"):
        assert apply(_object_message(object_id, 1, (0.0, 0.0, 0.0))).status == NodeStatus.SUCCESS


def test_the_next_plan_avoids_an_added_box_and_validation_names_it(
    behavior: Any, context: BehaviorContext, at_home: Any, lab_sim_model: Any
) -> None:
    from kinema.motion import fk

    straight = tick_behavior(
        behavior("PlanToJointGoal"), {"joint_goal": _joint_state(MID)}, context=context, timeout=30.0
    )
    assert straight.status == NodeStatus.SUCCESS, straight.toasts
    # a box where the tool passes halfway along the straight motion
    halfway = fk(lab_sim_model, _q(lab_sim_model, list((np.array(HOME) + np.array(MID)) / 2)), "grasp_link")
    x, y, z = halfway[:3, 3]
    add = tick_behavior(
        behavior("AddCollisionBox"),
        {"object_id": "obstacle", "dimensions": "0.12;0.12;0.12", "pose": _pose("world", (x, y, z))},
        context=context,
    )
    assert add.status == NodeStatus.SUCCESS, add.toasts
    check = tick_behavior(
        behavior("ValidateTrajectory"),
        {"joint_trajectory_msg": straight.outputs["joint_trajectory_msg"]},
        context=context,
        timeout=30.0,
    )
    assert check.status == NodeStatus.FAILURE and "obstacle" in check.toasts[-1], check.toasts
    around = tick_behavior(
        behavior("PlanToJointGoal"), {"joint_goal": _joint_state(MID)}, context=context, timeout=60.0
    )
    assert around.status == NodeStatus.SUCCESS, around.toasts
    valid = tick_behavior(
        behavior("ValidateTrajectory"),
        {"joint_trajectory_msg": around.outputs["joint_trajectory_msg"]},
        context=context,
        timeout=30.0,
    )
    assert valid.status == NodeStatus.SUCCESS, valid.toasts


def test_validation_ignores_a_finger_a_hair_past_its_stop_and_names_an_arm_joint_past_its_limit(
    behavior: Any, context: BehaviorContext, lab_sim_model: Any
) -> None:
    """The simulated gripper can rest micro-units past its limit; only the trajectory's joints are judged."""
    finger = lab_sim_model.lower[lab_sim_model.joint_names.index(GRIPPER)] - 5e-6
    state = {"name": [*ARM, GRIPPER], "position": [*HOME, finger]}
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        turn = [*HOME[:6], 0.5]
        valid = tick_behavior(
            behavior("ValidateTrajectory"),
            {"joint_trajectory_msg": _trajectory_through(HOME, turn)},
            context=context,
            timeout=30.0,
        )
        assert valid.status == NodeStatus.SUCCESS, valid.toasts
        elbow = lab_sim_model.upper[lab_sim_model.joint_names.index("elbow_joint")] + 0.01
        outside = _trajectory_through([*HOME[:3], elbow, *HOME[4:]], HOME)
        check = tick_behavior(
            behavior("ValidateTrajectory"), {"joint_trajectory_msg": outside}, context=context, timeout=30.0
        )
    assert check.status == NodeStatus.FAILURE, check.toasts
    assert "elbow_joint=" in check.toasts[-1] and "outside the joint limits" in check.toasts[-1], check.toasts


# -- trajectories ----------------------------------------------------------------------------------


def _trajectory_through(start: list[float], end: list[float]) -> Any:
    points = [
        {"positions": start, "time_from_start": {"sec": 0, "nanosec": 0}},
        {"positions": end, "time_from_start": {"sec": 2, "nanosec": 0}},
    ]
    return from_dict("trajectory_msgs/msg/JointTrajectory", {"joint_names": ARM, "points": points})


def _trajectory() -> Any:
    return _trajectory_through(HOME, MID)


@pytest.mark.parametrize(
    ("from_start", "seconds", "expected"),
    [(True, 0.0, HOME), (False, 0.0, MID), (True, 1.0, list((np.array(HOME) + np.array(MID)) / 2))],
)
def test_robot_state_from_trajectory(
    behavior: Any, context: BehaviorContext, from_start: bool, seconds: float, expected: list[float]
) -> None:
    run = tick_behavior(
        behavior("GetRobotStateFromTrajectory"),
        {"joint_trajectory_msg": _trajectory(), "from_start": from_start, "time_from_reference": seconds},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert list(run.outputs["joint_state"].name) == ARM
    np.testing.assert_allclose(run.outputs["joint_state"].position, expected, atol=1e-9)


def test_robot_state_from_trajectory_outside_its_time_names_the_range(
    behavior: Any, context: BehaviorContext
) -> None:
    run = tick_behavior(
        behavior("GetRobotStateFromTrajectory"),
        {"joint_trajectory_msg": _trajectory(), "time_from_reference": 3.5},
        context=context,
    )
    assert run.status == NodeStatus.FAILURE and "valid: 0 .. 2 s" in run.toasts[-1]


def test_stationary_trajectory_holds_the_state(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(
        behavior("CreateStationaryTrajectory"),
        {"joint_state": _joint_state(MID), "trajectory_duration": 10.0},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    points = run.outputs["joint_trajectory_msg"].points
    assert [p.time_from_start.sec for p in points] == [0, 10]
    np.testing.assert_allclose(points[1].positions, MID)
    assert not any(points[1].velocities)
    bad = tick_behavior(
        behavior("CreateStationaryTrajectory"),
        {"joint_state": _joint_state(MID), "trajectory_duration": 0.0},
        context=context,
    )
    assert bad.status == NodeStatus.FAILURE and "[trajectory_duration]" in bad.toasts[-1]


def test_cartesian_path_honours_tip_offset_and_refuses_unknown_timing(
    behavior: Any, context: BehaviorContext, at_home: Any, lab_sim_model: Any
) -> None:
    from kinema.motion import fk

    start = fk(lab_sim_model, _q(lab_sim_model, HOME), "grasp_link")
    target = start.copy()
    target[2, 3] -= 0.05
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(target[:3, :3]).as_quat()
    goal = _pose("world", tuple(target[:3, 3]), (x, y, z, w))
    plain = tick_behavior(behavior("PlanCartesianPath"), {"path": [goal]}, context=context, timeout=30.0)
    offset = tick_behavior(
        behavior("PlanCartesianPath"),
        {"path": [goal], "tip_offset": "0;0;0.05;0;0;0", "tip_links": "grasp_link"},
        context=context,
        timeout=30.0,
    )
    assert plain.status == NodeStatus.SUCCESS, plain.toasts
    assert offset.status == NodeStatus.SUCCESS, offset.toasts
    end_plain = _q(lab_sim_model, list(plain.outputs["joint_trajectory_msg"].points[-1].positions))
    end_offset = _q(lab_sim_model, list(offset.outputs["joint_trajectory_msg"].points[-1].positions))
    # with the point 5 cm out along the tool axis on the target, the grasp link stops 5 cm short of it
    grasp_z = fk(lab_sim_model, end_offset, "grasp_link")[2, 3]
    assert grasp_z == pytest.approx(fk(lab_sim_model, end_plain, "grasp_link")[2, 3] + 0.05, abs=2e-3)
    timing = tick_behavior(
        behavior("PlanCartesianPath"),
        {"path": [goal], "trajectory_timing": "[{mode: constant_velocity}]"},
        context=context,
        timeout=30.0,
    )
    assert timing.status == NodeStatus.FAILURE and "valid: time_optimal" in timing.toasts[-1]


def _empty_trajectory() -> Any:
    return from_dict("trajectory_msgs/msg/JointTrajectory", {"joint_names": ARM, "points": []})


def _unknown_joint_trajectory() -> Any:
    points = [{"positions": [0.0], "time_from_start": {"sec": 0, "nanosec": 0}}]
    return from_dict("trajectory_msgs/msg/JointTrajectory", {"joint_names": ["elbow"], "points": points})


@pytest.mark.parametrize(
    ("behavior_id", "inputs", "expected"),
    [
        (
            "ValidateTrajectory",
            {"joint_trajectory_msg": _unknown_joint_trajectory()},
            "unknown joint(s) elbow",
        ),
        (
            "ValidateTrajectory",
            {"joint_trajectory_msg": _trajectory(), "joint_space_step": 0.0},
            "[joint_space_step] = 0",
        ),
        (
            "ValidateTrajectory",
            {"joint_trajectory_msg": _trajectory(), "planning_group_name": "arm"},
            "[planning_group_name] = 'arm'",
        ),
        ("GetRobotStateFromTrajectory", {"joint_trajectory_msg": _empty_trajectory()}, "has no points"),
        (
            "IsCollisionObjectInPlanningScene",
            {"planning_scene": "nothing", "collision_object_name": "x"},
            "[planning_scene]",
        ),
        ("ComputeLinkPoseForwardKinematics", {"joint_state": "1;2;3"}, "[joint_state]"),
    ],
)
def test_bad_input_fails_the_behavior_naming_the_port(
    behavior: Any, context: BehaviorContext, at_home: Any, behavior_id: str, inputs: dict, expected: str
) -> None:
    run = tick_behavior(behavior(behavior_id), inputs, context=context, timeout=30.0)
    assert run.status == NodeStatus.FAILURE
    assert expected in run.toasts[-1], run.toasts


def test_cartesian_path_honours_ik_joint_space_density(
    behavior: Any, context: BehaviorContext, at_home: Any, lab_sim_model: Any
) -> None:
    from scipy.spatial.transform import Rotation

    from kinema.motion import fk

    target = fk(lab_sim_model, _q(lab_sim_model, HOME), "grasp_link")
    target[0, 3] += 0.05
    x, y, z, w = Rotation.from_matrix(target[:3, :3]).as_quat()
    goal = _pose("world", tuple(target[:3, 3]), (x, y, z, w))
    inputs = {"path": [goal], "ik_cartesian_space_density": 0.01}
    assert tick_behavior(behavior("PlanCartesianPath"), inputs, context=context, timeout=30.0).status == (
        NodeStatus.SUCCESS
    )
    strict = tick_behavior(
        behavior("PlanCartesianPath"),
        {**inputs, "ik_joint_space_density": 1e-4},
        context=context,
        timeout=30.0,
    )
    assert strict.status == NodeStatus.FAILURE and "exceeds the threshold 0.0001 at [" in strict.toasts[-1]
    # Where, and what it usually means (a new user read only the numbers for a target out of reach).
    assert "the edge of the arm's reach or a singularity there" in strict.toasts[-1]
    assert "a larger threshold allows the jump" in strict.toasts[-1]


def test_a_camera_of_the_scene_is_a_frame(behavior: Any, context: BehaviorContext, at_home: Any) -> None:
    run = tick_behavior(
        behavior("TransformPoseFrame"),
        {"input_pose": _pose("scene_camera", (0, 0, 0)), "target_frame_id": "world"},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    np.testing.assert_allclose(_xyz(run.outputs["output_pose"]), [0.0, 2.1, 1.624], atol=1e-6)
