"""Motion behaviors and ports MoveIt Pro's example workspace objectives use: GeneratePointToPointTrajectory,
ComputeInverseKinematics, CreateRobotState's joint_state_msg/velocities, PlanToJointGoal's seed,
max_iterations and trajectory_sampling_rate (kinova_sim demo_trajectory_stitching.xml, multi_arm_sim
multi_tip_pose_ik_example.xml, hangar_sim compute_ik_plan_and_move.xml)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
import yaml

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.resources import bundled_dir
from kinema.testing import build_tree, publish_repeatedly, run_objective, tick_behavior

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
THROUGH_TABLE = [0.0, 0.0, -0.3, 1.9, -1.6, -1.5708, 0.0]


def _seconds(duration: Any) -> float:
    return float(duration.sec + duration.nanosec * 1e-9)


def _joint_state(positions: list[float], velocities: list[float] | None = None) -> Any:
    from kinema.transport import from_dict

    return from_dict(
        "sensor_msgs/msg/JointState", {"name": ARM, "position": positions, "velocity": velocities or []}
    )


def _pose(frame: str, matrix: np.ndarray) -> Any:
    from kinema import transforms
    from kinema.transport import from_dict

    return from_dict(
        "geometry_msgs/msg/PoseStamped", {"header": {"frame_id": frame}, "pose": transforms.pose_dict(matrix)}
    )


def _q(model: Any, arm: list[float]) -> np.ndarray:
    return model.configuration(dict(zip(ARM, arm, strict=True)))


@pytest.fixture
def robot_at() -> Any:
    """``with robot_at(context, positions):`` the fake driver reports the arm there, gripper open."""

    def at(context: BehaviorContext, positions: list[float]) -> Any:
        state = {"name": [*ARM, GRIPPER], "position": [*positions, 0.0]}
        return publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state)

    return at


# --- GeneratePointToPointTrajectory ---------------------------------------------------------------------


def _p2p(behavior: Any, context: BehaviorContext, **inputs: Any) -> Any:
    ports = {"start_state": _joint_state(HOME), "target_state": _joint_state(MID)}
    ports.update(inputs)
    return tick_behavior(behavior("GeneratePointToPointTrajectory"), ports, context=context, timeout=60.0)


def test_point_to_point_goes_from_start_to_target_at_the_rate_from_start_time(
    behavior: Any, context: BehaviorContext
) -> None:
    run = _p2p(behavior, context, start_time=0.8, trajectory_sampling_rate=50.0, velocity_scale_factor=0.5)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    trajectory = run.outputs["joint_trajectory_msg"]
    assert list(trajectory.joint_names) == ARM
    np.testing.assert_allclose(trajectory.points[0].positions, HOME, atol=1e-9)
    np.testing.assert_allclose(trajectory.points[-1].positions, MID, atol=1e-9)
    times = np.array([_seconds(p.time_from_start) for p in trajectory.points])
    assert times[0] == pytest.approx(0.8)
    steps = np.diff(times)
    np.testing.assert_allclose(steps[:-1], 1 / 50, atol=2e-9)  # nanosecond rounding of each stamp
    assert 0 < steps[-1] <= 1 / 50 + 1e-9
    np.testing.assert_allclose(trajectory.points[0].velocities, 0.0)
    np.testing.assert_allclose(trajectory.points[-1].velocities, 0.0)
    limits = np.array([context.robot_model.limits[j].max_velocity for j in ARM])
    speeds = np.abs(np.array([p.velocities for p in trajectory.points]))
    assert (speeds <= 0.5 * limits + 1e-6).all()
    assert (speeds.max(axis=0) > 0.3 * limits).any()  # not needlessly slow either


def test_point_to_point_scale_factors_and_rate_change_the_trajectory(
    behavior: Any, context: BehaviorContext
) -> None:
    def timing(**inputs: Any) -> tuple[float, int]:
        run = _p2p(behavior, context, **inputs)
        assert run.status == NodeStatus.SUCCESS, run.toasts
        points = run.outputs["joint_trajectory_msg"].points
        return _seconds(points[-1].time_from_start), len(points)

    fast, fast_points = timing()
    slow, _ = timing(velocity_scale_factor=0.2, acceleration_scale_factor=0.2)
    assert slow > 2 * fast
    _, sparse_points = timing(trajectory_sampling_rate=10.0)
    assert sparse_points == pytest.approx(fast_points / 10, abs=2)


@pytest.mark.parametrize(
    ("inputs", "port", "says"),
    [
        ({"target_state": _joint_state([*MID[:-1], 0.0])}, "", ""),  # sanity: a valid target
        ({"jerk_scale_factor": 0.0}, "jerk_scale_factor", "expected a fraction in (0, 1]"),
        ({"trajectory_sampling_rate": 0.0}, "trajectory_sampling_rate", "points per second > 0"),
        ({"start_time": -1.0}, "start_time", "expected seconds >= 0"),
        (
            {"start_state": _joint_state(HOME, [0.5, 0, 0, 0, 0, 0, 0])},
            "start_state",
            "is moving (linear_rail_joint at 0.5/s)",
        ),
        (
            {"target_state": _joint_state([*MID[:2], 1.0, *MID[3:]])},
            "target_state",
            "puts shoulder_lift_joint at 1.0000, outside its limits",
        ),
    ],
    ids=["valid", "jerk", "rate", "start_time", "moving", "limits"],
)
def test_point_to_point_refuses_what_it_cannot_do_naming_the_port(
    behavior: Any, context: BehaviorContext, inputs: dict[str, Any], port: str, says: str
) -> None:
    run = _p2p(behavior, context, **inputs)
    if not port:
        assert run.status == NodeStatus.SUCCESS, run.toasts
        return
    assert run.status == NodeStatus.FAILURE
    assert f"[{port}]" in run.toasts[-1] and says in run.toasts[-1], run.toasts


def test_point_to_point_needs_every_joint_of_the_group(behavior: Any, context: BehaviorContext) -> None:
    from kinema.transport import from_dict

    partial = from_dict("sensor_msgs/msg/JointState", {"name": ARM[1:], "position": MID[1:]})
    run = _p2p(behavior, context, target_state=partial)
    assert run.status == NodeStatus.FAILURE
    assert "lacks joint(s) linear_rail_joint of group 'manipulator'" in run.toasts[-1], run.toasts


# --- CreateRobotState ------------------------------------------------------------------------------------


def test_create_robot_state_writes_a_joint_state_with_velocities(behavior: Any) -> None:
    xml = """<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence>
      <Action ID="CreateRobotState" joint_names="a;b" positions="0.5;1.5" velocities="0.1;-0.2"
              joint_state_msg="{with_velocities}" />
      <Action ID="CreateRobotState" joint_names="a;b" positions="0.5;1.5" velocities="{nothing}"
              joint_state_msg="{without}" robot_state="{robot_state}" />
    </Sequence></BehaviorTree></root>"""
    tree = build_tree(xml, behaviors=[behavior("CreateRobotState")])
    tree.root_blackboard.set("nothing", [])  # what UnpackJointStateMessage gives for a state without any
    assert tree.tick_while_running() == NodeStatus.SUCCESS
    state = tree.root_blackboard.get("with_velocities")
    assert state.__msgtype__ == "sensor_msgs/msg/JointState"
    assert list(state.name) == ["a", "b"]
    np.testing.assert_allclose(state.position, [0.5, 1.5])
    np.testing.assert_allclose(state.velocity, [0.1, -0.2])
    assert len(tree.root_blackboard.get("without").velocity) == 0
    np.testing.assert_allclose(tree.root_blackboard.get("joint_state_msg").joint_state.velocity, [0.1, -0.2])
    assert tree.root_blackboard.get("robot_state").joint_state.position.tolist() == [0.5, 1.5]


def test_create_robot_state_wants_one_velocity_per_joint(behavior: Any) -> None:
    run = tick_behavior(
        behavior("CreateRobotState"), {"joint_names": "a;b", "positions": "0;1", "velocities": "0.1"}
    )
    assert run.status == NodeStatus.FAILURE
    assert "2 joint names but 1 velocities" in run.toasts[-1], run.toasts


# --- ComputeInverseKinematics ----------------------------------------------------------------------------


def _ik(behavior: Any, context: BehaviorContext, poses: list[Any], tips: str, **inputs: Any) -> Any:
    ports = {"target_poses": poses, "tip_links": tips, "planning_group_name": "manipulator", **inputs}
    return tick_behavior(behavior("ComputeInverseKinematics"), ports, context=context, timeout=60.0)


def _solved(context: BehaviorContext, run: Any) -> np.ndarray:
    assert run.status == NodeStatus.SUCCESS, run.toasts
    solution = run.outputs["solution"]
    assert solution.__msgtype__ == "sensor_msgs/msg/JointState"
    assert list(solution.name) == ARM  # the group's joints: a goal PlanToJointGoal takes
    return _q(context.robot_model, list(solution.position))


def _assert_reaches(model: Any, q: np.ndarray, link: str, target: np.ndarray) -> None:
    from kinema.motion import fk

    reached = fk(model, q, link)
    np.testing.assert_allclose(reached[:3, 3], target[:3, 3], atol=1e-3)
    np.testing.assert_allclose(reached[:3, :3], target[:3, :3], atol=1e-2)


def test_ik_puts_the_tip_at_the_target_from_the_current_state(
    behavior: Any, context: BehaviorContext, robot_at: Any
) -> None:
    from kinema.motion import fk

    model = context.robot_model
    target = fk(model, _q(model, MID), "grasp_link")
    with robot_at(context, HOME):
        q = _solved(context, _ik(behavior, context, [_pose("world", target)], "grasp_link"))
    _assert_reaches(model, q, "grasp_link", target)


def test_ik_reads_a_pose_in_a_robot_link_frame_as_hangar_sim_does(
    behavior: Any, context: BehaviorContext, robot_at: Any
) -> None:
    from kinema.motion import fk

    model = context.robot_model
    ahead = np.eye(4)
    ahead[2, 3] = 0.1  # 10 cm along the gripper's approach axis
    with robot_at(context, MID):
        q = _solved(context, _ik(behavior, context, [_pose("grasp_link", ahead)], "grasp_link"))
    _assert_reaches(model, q, "grasp_link", fk(model, _q(model, MID), "grasp_link") @ ahead)


def test_ik_solves_several_tips_at_once(behavior: Any, context: BehaviorContext, robot_at: Any) -> None:
    from kinema.motion import fk

    model = context.robot_model
    q_mid = _q(model, MID)
    tips = ["grasp_link", "forearm_link"]
    targets = [fk(model, q_mid, tip) for tip in tips]
    with robot_at(context, HOME):
        run = _ik(behavior, context, [_pose("world", t) for t in targets], ";".join(tips))
        q = _solved(context, run)
    for tip, target in zip(tips, targets, strict=True):
        _assert_reaches(model, q, tip, target)


def test_ik_out_of_reach_or_only_in_collision_fails_saying_why(
    behavior: Any, context: BehaviorContext, robot_at: Any
) -> None:
    from kinema.motion import fk

    model = context.robot_model
    far = np.eye(4)
    far[:3, 3] = [5.0, 0.0, 1.0]
    under_the_table = fk(model, _q(model, THROUGH_TABLE), "grasp_link")
    with robot_at(context, HOME):
        run = _ik(behavior, context, [_pose("world", far)], "grasp_link")
        assert run.status == NodeStatus.FAILURE
        assert run.toasts[-1].startswith("ComputeInverseKinematics: no IK solution for 'grasp_link'")
        assert "out of reach" in run.toasts[-1]
        run = _ik(behavior, context, [_pose("world", under_the_table)], "grasp_link")
        assert run.status == NodeStatus.FAILURE
        assert "rejected (e.g. in collision)" in run.toasts[-1], run.toasts


def test_ik_link_padding_keeps_solutions_away_from_the_scene(
    behavior: Any, context: BehaviorContext, robot_at: Any
) -> None:
    from kinema.motion import fk

    model = context.robot_model
    target = [_pose("world", fk(model, _q(model, MID), "grasp_link"))]
    with robot_at(context, HOME):
        assert _ik(behavior, context, target, "grasp_link", link_padding=0.0).status == NodeStatus.SUCCESS
        padded = _ik(behavior, context, target, "grasp_link", link_padding=0.5)
    assert padded.status == NodeStatus.FAILURE
    assert "rejected (e.g. in collision)" in padded.toasts[-1], padded.toasts


def test_ik_wants_one_known_tip_per_pose(behavior: Any, context: BehaviorContext, robot_at: Any) -> None:
    pose = _pose("world", np.eye(4))
    with robot_at(context, HOME):
        run = _ik(behavior, context, [pose], "grasp_link;tool0")
        assert run.status == NodeStatus.FAILURE
        assert "names 2 link(s) for 1 target pose(s)" in run.toasts[-1]
        run = _ik(behavior, context, [pose], "grasp_lnk")
        assert run.status == NodeStatus.FAILURE
        assert "grasp_link" in run.toasts[-1]  # did you mean


# --- PlanToJointGoal's new ports -------------------------------------------------------------------------


def test_plan_to_joint_goal_samples_at_the_rate(
    behavior: Any, context: BehaviorContext, robot_at: Any
) -> None:
    with robot_at(context, HOME):
        runs = [
            tick_behavior(
                behavior("PlanToJointGoal"),
                {"joint_goal": _joint_state(MID), "trajectory_sampling_rate": rate},
                context=context,
                timeout=120.0,
            )
            for rate in (100.0, 20.0)
        ]
    for run in runs:
        assert run.status == NodeStatus.SUCCESS, run.toasts
    dense, sparse = (run.outputs["joint_trajectory_msg"].points for run in runs)
    sparse_steps = np.diff([_seconds(p.time_from_start) for p in sparse])
    assert sparse_steps.max() <= 1 / 20 + 1e-9 and sparse_steps.min() > 1 / 20 * 0.9
    assert len(dense) > 4 * len(sparse)


def _waypoint(name: str) -> list[float]:
    path = bundled_dir("configs") / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml"
    entry = next(e for e in yaml.safe_load(path.read_text()) if e["name"] == name)
    by_name = dict(zip(entry["joint_state"]["name"], entry["joint_state"]["position"], strict=True))
    return [float(by_name[j]) for j in ARM]


def test_plan_to_joint_goal_seed_repeats_the_search_and_max_iterations_caps_it(
    behavior: Any, context: BehaviorContext, robot_at: Any
) -> None:
    from kinema.motion import fk

    model = context.robot_model
    start, goal = _waypoint("3 Waypoint Mid Point"), _waypoint("3 Waypoint Pick Pose")
    block = np.eye(4)
    block[:3, 3] = (fk(model, _q(model, start), "grasp_link") + fk(model, _q(model, goal), "grasp_link"))[
        :3, 3
    ] / 2
    context.planning_scene.add_box("block", (0.03, 0.03, 0.03), block)  # across the straight move

    def plan(**inputs: Any) -> Any:
        ports = {"joint_goal": _joint_state(goal), "planning_time": 10.0, **inputs}
        return tick_behavior(behavior("PlanToJointGoal"), ports, context=context, timeout=120.0)

    with robot_at(context, start):
        first, again, other = plan(seed=2), plan(seed=2), plan(seed=0)
        capped = plan(seed=2, max_iterations=1)  # seed 0 happens to connect after one sample
    paths = []
    for run in (first, again, other):
        assert run.status == NodeStatus.SUCCESS, run.toasts
        paths.append(np.array([p.positions for p in run.outputs["joint_trajectory_msg"].points]))
    np.testing.assert_array_equal(paths[0], paths[1])
    assert paths[0].shape != paths[2].shape or not np.array_equal(paths[0], paths[2])
    assert capped.status == NodeStatus.FAILURE
    assert "in 1 iterations (seeded RRT-Connect, seed 2)" in capped.toasts[-1], capped.toasts


# --- the example objectives' calls, port for port --------------------------------------------------------

EXAMPLE_CALLS = """<root BTCPP_format="4" main_tree_to_execute="Calls">
  <BehaviorTree ID="Calls">
    <Sequence>
      <!-- MoveIt Pro's demo fills these with GetJointState and UnpackJointStateMessage -->
      <Script code="joint_names:='ARM_JOINTS'" />
      <Script code="start_position:='0.0;0.0;-2.0;2.0;-1.5708;-1.5708;0.0'; start_velocity:=''" />
      <Action ID="GetCurrentPlanningScene" planning_scene_msg="{planning_scene}" />
      <Action ID="CreateRobotState" joint_state_msg="{start_state}" positions="{start_position}"
        joint_names="{joint_names}" velocities="{start_velocity}" />
      <Action ID="CreateRobotState" positions="-0.1333;0.0;-1.25758;1.37827;-1.69149;-1.5708;0.0"
        joint_names="{joint_names}" joint_state_msg="{target_state}"
        velocities="0.0;0.0;0.0;0.0;0.0;0.0;0.0" />
      <Action ID="CreateRobotState" positions="0.0;0.2;-1.25758;1.37827;-1.69149;-1.5708;0.0"
        joint_names="{joint_names}" joint_state_msg="{stitch_target_state}"
        velocities="0.0;0.0;0.0;0.0;0.0;0.0;0.0" />
      <Action ID="GeneratePointToPointTrajectory" jerk_scale_factor="0.5" velocity_scale_factor="1.0"
        acceleration_scale_factor="1.0" planning_group_name="manipulator" start_state="{start_state}"
        start_time="0.000000" target_state="{target_state}" trajectory_sampling_rate="100"
        joint_trajectory_msg="{joint_trajectory_msg}" />
      <Action ID="GetRobotStateFromTrajectory" time_from_reference="0.8" joint_state="{stitch_state}"
        from_start="true" joint_trajectory_msg="{joint_trajectory_msg}" />
      <Action ID="GeneratePointToPointTrajectory" start_state="{stitch_state}"
        target_state="{stitch_target_state}" joint_trajectory_msg="{stitch_joint_trajectory_msg}"
        velocity_scale_factor="1.0" start_time="0.8" acceleration_scale_factor="1.0"
        jerk_scale_factor="0.5" planning_group_name="manipulator" trajectory_sampling_rate="100" />
      <Action ID="CreatePoseStamped" reference_frame="grasp_link" pose_stamped="{target_pose}"
        position_xyz="0;0;0.1" />
      <Action ID="ResetVector" vector="{target_poses}" />
      <Action ID="PushBackVector" input_vector="{target_poses}" element="{target_pose}"
        output_vector="{target_poses}" />
      <Action ID="ComputeInverseKinematics" ik_timeout_s="0.05" link_padding="0.01"
        planning_group_name="manipulator" planning_scene_msg="{planning_scene}"
        target_poses="{target_poses}" tip_links="grasp_link" solution="{joint_space_solution}" />
      <Action ID="ComputeInverseKinematics" ik_timeout_s="0.01" planning_group_name="manipulator"
        planning_scene_msg="{planning_scene}" target_poses="{target_poses}" tip_links="grasp_link"
        solution="{solution}" />
      <Action ID="PlanToJointGoal" acceleration_scale_factor="1.000000"
        joint_goal="{joint_space_solution}" joint_trajectory_msg="{joint_trajectory_msg}"
        link_padding="0.000000" max_iterations="5000" planning_group_name="manipulator" seed="0"
        trajectory_sampling_rate="100" velocity_scale_factor="1.000000" />
    </Sequence>
  </BehaviorTree>
</root>""".replace("ARM_JOINTS", ";".join(ARM))


def test_the_example_objectives_calls_run_port_for_port(
    registry: Any, context: BehaviorContext, robot_at: Any
) -> None:
    from kinema.motion import fk

    model = context.robot_model
    with robot_at(context, HOME):
        result = run_objective(EXAMPLE_CALLS, registry=registry, context=context, timeout=120.0)
    assert result.status == NodeStatus.SUCCESS, result.toasts
    board = result.blackboard
    stitched = board["stitch_joint_trajectory_msg"]
    assert _seconds(stitched.points[0].time_from_start) == pytest.approx(0.8)
    np.testing.assert_allclose(stitched.points[-1].positions, [0.0, 0.2, *MID[2:]], atol=1e-9)
    ahead = np.eye(4)
    ahead[2, 3] = 0.1
    target = fk(model, _q(model, HOME), "grasp_link") @ ahead
    for key in ("joint_space_solution", "solution"):
        _assert_reaches(model, _q(model, list(board[key].position)), "grasp_link", target)
    # PlanToJointGoal took the IK solution as its goal, from the arm's current state
    planned = board["joint_trajectory_msg"]
    np.testing.assert_allclose(planned.points[0].positions, HOME, atol=1e-6)
    np.testing.assert_allclose(
        planned.points[-1].positions, board["joint_space_solution"].position, atol=1e-6
    )
