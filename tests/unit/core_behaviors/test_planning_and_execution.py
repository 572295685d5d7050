"""PlanToJointGoal, PlanCartesianPath, ExecuteTrajectory: lab_sim model, fake joint states and controllers."""

from __future__ import annotations

import threading
import time
from typing import Any

import numpy as np
import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import build_tree, publish_repeatedly, tick_behavior

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


@pytest.fixture
def at_home(context: BehaviorContext) -> Any:
    """The fake driver reports the arm at Home, gripper open."""
    state = {"name": [*ARM, GRIPPER], "position": [*HOME, 0.0]}
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        yield


def _goal(positions: list[float]) -> Any:
    from kinema.transport import from_dict

    return from_dict("sensor_msgs/msg/JointState", {"name": ARM, "position": positions})


def test_plan_to_joint_goal_times_a_path_from_the_current_state(
    behavior: Any, context: BehaviorContext, at_home: Any
) -> None:
    run = tick_behavior(
        behavior("PlanToJointGoal"),
        {"joint_goal": _goal(MID), "velocity_scale_factor": 0.5},
        context=context,
        timeout=120.0,  # the first plan of the module loads the robot model and collision geometry
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    trajectory = run.outputs["joint_trajectory_msg"]
    assert list(trajectory.joint_names) == ARM
    np.testing.assert_allclose(trajectory.points[0].positions, HOME, atol=1e-6)
    np.testing.assert_allclose(trajectory.points[-1].positions, MID, atol=1e-6)
    last = trajectory.points[-1].time_from_start
    assert last.sec + last.nanosec * 1e-9 > 0.2
    # velocity_scale_factor 0.5 keeps every joint at half its limit or below
    limits = np.array([context.robot_model.limits[j].max_velocity for j in ARM])
    speeds = np.abs(np.array([p.velocities for p in trajectory.points]))
    assert (speeds <= 0.5 * limits + 1e-6).all()


@pytest.mark.parametrize(
    "written",
    [
        {"name": ARM, "position": MID},
        {"joint_state": {"name": ARM, "position": MID}},
        dict(zip(ARM, MID, strict=True)),
    ],
    ids=["JointState", "RobotJointState", "joint map"],
)
def test_a_joint_goal_written_out_as_yaml_plans_like_the_message(
    behavior: Any, context: BehaviorContext, at_home: Any, written: dict[str, Any]
) -> None:
    # What `-p target_joint_state={name: [...], position: [...]}` or a YAML file hands the port: a dict.
    run = tick_behavior(behavior("PlanToJointGoal"), {"joint_goal": written}, context=context, timeout=120.0)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    np.testing.assert_allclose(run.outputs["joint_trajectory_msg"].points[-1].positions, MID, atol=1e-6)


def test_a_joint_goal_dict_of_the_wrong_shape_says_which_shapes_work(
    behavior: Any, context: BehaviorContext, at_home: Any
) -> None:
    run = tick_behavior(
        behavior("PlanToJointGoal"), {"joint_goal": {"name": ARM, "position": 0.5}}, context=context
    )
    assert run.status == NodeStatus.FAILURE
    assert "a JointState's name and position are lists" in run.toasts[-1], run.toasts
    run = tick_behavior(behavior("PlanToJointGoal"), {"joint_goal": {"elbow_joint": [1.0]}}, context=context)
    assert run.status == NodeStatus.FAILURE
    assert "{name: [joint1, joint2], position: [0.0, 1.57]}" in run.toasts[-1], run.toasts


def test_a_goal_in_collision_fails_naming_the_links(
    behavior: Any, context: BehaviorContext, at_home: Any
) -> None:
    run = tick_behavior(behavior("PlanToJointGoal"), {"joint_goal": _goal(THROUGH_TABLE)}, context=context)
    assert run.status == NodeStatus.FAILURE
    assert run.toasts[-1].startswith("PlanToJointGoal: planning failed: goal state is in collision")
    assert "table" in run.toasts[-1]


def test_a_goal_outside_the_limits_or_group_fails(
    behavior: Any, context: BehaviorContext, at_home: Any
) -> None:
    beyond = list(MID)
    beyond[2] = 1.0  # shoulder_lift_joint's upper limit is 0
    run = tick_behavior(behavior("PlanToJointGoal"), {"joint_goal": _goal(beyond)}, context=context)
    assert run.status == NodeStatus.FAILURE and "outside its limits" in run.toasts[-1]
    group = tick_behavior(
        behavior("PlanToJointGoal"),
        {"joint_goal": _goal(MID), "planning_group_name": "manipulatr"},
        context=context,
    )
    assert group.status == NodeStatus.FAILURE and "unknown planning group 'manipulatr'" in group.toasts[-1]


def test_planning_without_a_driver_says_so(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(
        behavior("PlanToJointGoal"), {"joint_goal": _goal(MID)}, context=context, timeout=30.0
    )
    assert run.status == NodeStatus.FAILURE
    assert "no joint state received on /joint_states" in run.toasts[-1]


def test_an_orientation_constraint_is_refused_not_ignored(
    behavior: Any, context: BehaviorContext, at_home: Any
) -> None:
    run = tick_behavior(
        behavior("PlanToJointGoal"),
        {"joint_goal": _goal(MID), "orientation_constraint": "[0, 0, 0, 1]"},
        context=context,
    )
    assert run.status == NodeStatus.FAILURE and "orientation constraints are not supported" in run.toasts[-1]


def test_plan_cartesian_path_moves_the_tool_straight_down(
    behavior: Any, context: BehaviorContext, at_home: Any
) -> None:
    from kinema.motion import fk

    model = context.robot_model
    q = model.neutral().copy()
    q[: len(HOME)] = HOME
    start = fk(model, q, "grasp_link")
    pose = tick_behavior(
        behavior("CreatePoseStamped"),
        {
            "reference_frame": "grasp_link",
            "position_xyz": [0.0, 0.0, 0.05],  # 5 cm along the tool's own z axis
            "orientation_xyzw": [0.0, 0.0, 0.0, 1.0],
        },
        context=context,
    ).outputs["pose_stamped"]
    run = tick_behavior(behavior("PlanCartesianPath"), {"path": [pose]}, context=context, timeout=30.0)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    end = list(run.outputs["joint_trajectory_msg"].points[-1].positions)
    q_end = q.copy()
    q_end[: len(ARM)] = end
    moved = fk(model, q_end, "grasp_link")[:3, 3] - start[:3, 3]
    np.testing.assert_allclose(moved, start[:3, 2] * 0.05, atol=2e-3)


def _tool_pose(behavior: Any, context: BehaviorContext, xyz: list[float]) -> Any:
    return tick_behavior(
        behavior("CreatePoseStamped"),
        {"reference_frame": "grasp_link", "position_xyz": xyz, "orientation_xyzw": [0.0, 0.0, 0.0, 1.0]},
        context=context,
    ).outputs["pose_stamped"]


def test_plan_cartesian_path_rounds_corners_by_blending_radius(
    behavior: Any, context: BehaviorContext, at_home: Any
) -> None:
    from kinema.motion import fk

    model = context.robot_model
    q = model.neutral().copy()
    q[: len(HOME)] = HOME
    start = fk(model, q, "grasp_link")
    # 5 cm along the tool's z, then 5 cm along its x: a right angle 5 cm out
    path = [_tool_pose(behavior, context, [0.0, 0.0, 0.05]), _tool_pose(behavior, context, [0.05, 0.0, 0.05])]
    corner = (start @ np.array([0.0, 0.0, 0.05, 1.0]))[:3]
    closest = {}
    for radius in (0.0, 0.02):
        run = tick_behavior(
            behavior("PlanCartesianPath"),
            {"path": path, "blending_radius": radius},
            context=context,
            timeout=30.0,
        )
        assert run.status == NodeStatus.SUCCESS, run.toasts
        tool = []
        for point in run.outputs["joint_trajectory_msg"].points:
            q_point = q.copy()
            q_point[: len(ARM)] = list(point.positions)
            tool.append(fk(model, q_point, "grasp_link")[:3, 3])
        closest[radius] = float(np.linalg.norm(np.array(tool) - corner, axis=1).min())
    assert closest[0.0] < 2e-3, closest
    assert closest[0.02] == pytest.approx(0.02 * (np.sqrt(2) - 1), abs=2e-3), closest


def test_plan_cartesian_path_refuses_a_negative_blending_radius(
    behavior: Any, context: BehaviorContext, at_home: Any
) -> None:
    path = [_tool_pose(behavior, context, [0.0, 0.0, 0.05])]
    run = tick_behavior(
        behavior("PlanCartesianPath"), {"path": path, "blending_radius": -0.01}, context=context, timeout=30.0
    )
    assert run.status == NodeStatus.FAILURE
    assert "blending_radius must be >= 0 (m), got -0.01" in run.toasts[-1], run.toasts


class Controller:
    """A fake FollowJointTrajectory server."""

    def __init__(
        self, node: Any, *, error_code: int = 0, error: str = "", hold: bool = False, hang: bool = False
    ) -> None:
        self.goals: list[Any] = []
        self.hang = threading.Event() if hang else None
        self.cancelled = threading.Event()
        self.started = threading.Event()
        self.error_code, self.error, self.hold = error_code, error, hold
        self.server = node.create_action_server(
            "control_msgs/action/FollowJointTrajectory",
            "/joint_trajectory_controller/follow_joint_trajectory",
            self._execute,
        )

    def _execute(self, handle: Any) -> Any:
        self.goals.append(handle.goal)
        self.started.set()
        if self.hang is not None:  # a crashed driver: never answers again
            self.hang.wait(30.0)
            return None
        if self.hold:
            if handle.cancel_requested_event.wait(30.0):
                self.cancelled.set()
                handle.canceled({"error_code": 0, "error_string": "canceled; holding position"})
            return None
        result = {"error_code": self.error_code, "error_string": self.error}
        if self.error_code:
            handle.abort(result)
            return None
        return result


def _trajectory(names: list[str] = ARM) -> Any:
    from kinema.transport import from_dict

    points = [
        {"positions": [0.0] * len(names), "time_from_start": {"sec": 0, "nanosec": 0}},
        {"positions": [0.1] * len(names), "time_from_start": {"sec": 1, "nanosec": 0}},
    ]
    return from_dict("trajectory_msgs/msg/JointTrajectory", {"joint_names": names, "points": points})


def test_execute_trajectory_sends_the_trajectory_and_tolerances(
    behavior: Any, context: BehaviorContext
) -> None:
    controller = Controller(context.node)
    run = tick_behavior(
        behavior("ExecuteTrajectory"),
        {
            "joint_trajectory_msg": _trajectory(),
            "goal_position_tolerance": [0.01],  # a vector, as in MoveIt Pro (one value: every joint)
            "goal_duration_tolerance": 0.5,
        },
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    goal = controller.goals[0]
    assert list(goal.trajectory.joint_names) == ARM
    assert [t.position for t in goal.goal_tolerance] == [0.01] * len(ARM)
    assert goal.goal_time_tolerance.nanosec == 500_000_000
    assert len(goal.path_tolerance) == 0


def test_execute_trajectory_ends_once_the_joint_states_show_the_arm_at_the_end(
    behavior: Any, context: BehaviorContext
) -> None:
    """The controller's result can overtake its last joint states (a loaded machine); the next behavior
    plans from the latest state, so success waits until that state is the trajectory's end."""
    state = {"name": ARM, "position": [0.0] * len(ARM)}
    arrived = threading.Event()

    def report_the_end_late() -> None:
        state["position"] = [0.1] * len(ARM)
        arrived.set()

    def succeed_before_the_state_arrives(handle: Any) -> Any:
        threading.Timer(0.5, report_the_end_late).start()
        return {"error_code": 0, "error_string": ""}

    action = "/late_reporting_controller/follow_joint_trajectory"
    server = context.node.create_action_server(
        "control_msgs/action/FollowJointTrajectory", action, succeed_before_the_state_arrives
    )
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        context.joint_states.latest(timeout=5.0)  # in a cell, planning subscribed long before
        run = tick_behavior(
            behavior("ExecuteTrajectory"),
            {"joint_trajectory_msg": _trajectory(), "controller_action_name": action},
            context=context,
        )
        server.close()
        assert run.status == NodeStatus.SUCCESS, run.toasts
        assert arrived.is_set(), "ExecuteTrajectory succeeded while /joint_states still showed the start"
        monitor = context.joint_states
        assert monitor.positions(ARM) == pytest.approx([0.1] * len(ARM))


def test_a_rejected_trajectory_fails_with_the_controllers_error(
    behavior: Any, context: BehaviorContext
) -> None:
    Controller(context.node, error_code=-2, error="unknown joint 'elbow_jiont' (joints: elbow_joint, ...)")
    names = [*ARM[:3], "elbow_jiont"]
    run = tick_behavior(
        behavior("ExecuteTrajectory"), {"joint_trajectory_msg": _trajectory(names)}, context=context
    )
    assert run.status == NodeStatus.FAILURE
    assert "ABORTED" in run.toasts[-1] and "elbow_jiont" in run.toasts[-1]


def test_a_malformed_trajectory_is_refused_before_sending(behavior: Any, context: BehaviorContext) -> None:
    controller = Controller(context.node)
    empty = _trajectory()
    empty.points = []
    run = tick_behavior(behavior("ExecuteTrajectory"), {"joint_trajectory_msg": empty}, context=context)
    assert run.status == NodeStatus.FAILURE and "has no points" in run.toasts[-1]
    assert controller.goals == []


def test_halting_execute_trajectory_cancels_the_controller_goal(
    behavior: Any, registry: Any, context: BehaviorContext
) -> None:
    controller = Controller(context.node, hold=True)
    context.log_sink  # noqa: B018 - the tree shares the context's sink
    from kinema.bt import Blackboard

    blackboard = Blackboard.create()
    blackboard.set("joint_trajectory_msg", _trajectory())
    tree = build_tree(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Action ID="ExecuteTrajectory" /></BehaviorTree></root>',
        registry=registry,
        context=context,
        blackboard=blackboard,
    )
    deadline = time.monotonic() + 10
    while not controller.started.is_set() and time.monotonic() < deadline:
        assert tree.tick_once() == NodeStatus.RUNNING
        tree.sleep(0.01)
    halted = time.monotonic()
    tree.halt_tree()
    assert controller.cancelled.wait(5.0)
    # Within a tick or two unless the machine is overloaded; this bound only catches a halt that hangs.
    assert time.monotonic() - halted < 5.0


def test_a_controller_that_goes_away_fails_the_run_within_a_second(
    behavior: Any, registry: Any, context: BehaviorContext
) -> None:
    from kinema.transport import Node

    server_node = Node(context.node.session, "fake_driver")
    controller = Controller(server_node, hang=True)
    messages: list[Any] = []
    context.log_sink.subscribe(messages.append)
    from kinema.bt import Blackboard

    blackboard = Blackboard.create()
    blackboard.set("joint_trajectory_msg", _trajectory())
    tree = build_tree(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Action ID="ExecuteTrajectory" /></BehaviorTree></root>',
        registry=registry,
        context=context,
        blackboard=blackboard,
    )
    status = tree.tick_once()
    while not controller.started.is_set():
        status = tree.tick_once()
        tree.sleep(0.01)
    server_node.close()
    gone = time.monotonic()
    # Within about a second unless the machine is overloaded; 15 s only catches a run that would wait
    # for the lost controller's result for ever.
    while status == NodeStatus.RUNNING and time.monotonic() - gone < 15.0:
        tree.sleep(0.01)
        status = tree.tick_once()
    assert status == NodeStatus.FAILURE, f"still {status} {time.monotonic() - gone:.1f} s after it went away"
    assert "lost the controller" in messages[-1].text
    controller.hang.set()


def test_execute_mtc_solution_runs_the_planned_solution_on_the_controller(
    behavior: Any, context: BehaviorContext, at_home: None
) -> None:
    """MoveIt Pro's newer objectives execute a solution with ExecuteMTCSolution (hangar_sim's "Move to Pose
    No Preview"), where older ones call the "Execute MTC Solution" subtree: the same motion reaches the
    controller, with the ports those objectives set."""
    from kinema.transport import from_dict

    task = tick_behavior(behavior("InitializeMTCTask"), {"task_id": "t"}, context=context).outputs["task"]
    task = tick_behavior(behavior("SetupMTCCurrentState"), {"task": task}, context=context).outputs["task"]
    goal = from_dict("sensor_msgs/msg/JointState", {"name": ARM, "position": MID})
    task = tick_behavior(
        behavior("SetupMTCPlanToRobotState"), {"task": task, "joint_state": goal}, context=context
    ).outputs["task"]
    planned = tick_behavior(behavior("PlanMTCTask"), {"task": task}, context=context, timeout=60)
    assert planned.status == NodeStatus.SUCCESS, planned.toasts
    solution = planned.outputs["solution"]
    controller = Controller(context.node)
    run = tick_behavior(
        behavior("ExecuteMTCSolution"),
        {
            "solution": solution,
            "execution_pipeline": "jtc",
            "controller_action_name": "/joint_trajectory_controller/follow_joint_trajectory",
            "goal_duration_tolerance": -1.0,
        },
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    sent = controller.goals[0].trajectory
    joined = solution.joined()
    assert list(sent.joint_names) == list(joined.joint_names)
    assert np.allclose(sent.points[-1].positions, joined.positions[-1])
    # The half of a split before the first motion moves nothing: done, nothing sent (every joint's hold,
    # the gripper's too, went to the arm's controller, which refused it).
    from kinema.motion.solution_split import split_solution

    nothing = split_solution(solution, 1)[0]
    assert not nothing.sub_trajectories
    idle = tick_behavior(behavior("ExecuteMTCSolution"), {"solution": nothing}, context=context)
    assert idle.status == NodeStatus.SUCCESS and "moves nothing" in idle.toasts[-1], idle.toasts
    assert len(controller.goals) == 1
    refused = tick_behavior(behavior("ExecuteMTCSolution"), {"solution": task}, context=context)
    assert refused.status == NodeStatus.FAILURE
    assert "needs a solution PlanMTCTask planned, got" in refused.toasts[-1], refused.toasts
