"""MoveIt Pro's MTC behaviors: a pick task set up, planned and joined into one trajectory, offline on lab_sim.

The fake driver publishes lab_sim's "Look at Table" state; the tree is the planning half of MoveIt Pro's
"Pick from Pose" with the same behaviors and ports.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from test_lab_sim_library_validates import ADDED, BEFORE, CONFIG, corpus_workspace  # noqa: F401

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.resources import bundled_dir
from kinema.testing import publish_repeatedly, run_objective, tick_behavior

WAYPOINTS = bundled_dir("configs") / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml"
CUBE = (-0.3, 0.62, 0.504)
DOWN = "0;1;0;0"  # grasp_link's z axis pointing down, as at lab_sim's pick waypoint

# Issue 13: the pick and place objectives of lab_sim and what they reach.
TASK_PLANNING = {
    "add_poses_to_mtc_task",
    "add_waypoints_to_mtc_task",
    "get_collision_free_grasp_subtree",
    "move_along_square",
    "pick_from_pose",
    "pick_from_pose_vector",
    "pick_from_pose_with_approval",
    "pick_object",
    "place_at_pose",
    "place_at_pose_vector",
    "place_at_pose_with_approval",
    "place_object",
    "plan_move_to_pose",
    "record_square_trajectory",
}

PICK_PLAN = f"""
<root BTCPP_format="4" main_tree_to_execute="plan pick">
  <BehaviorTree ID="plan pick">
    <Sequence>
      <Action ID="InitializeMTCTask" task="{{mtc_task}}" task_id="pick_object" timeout="-1.000000" />
      <Action ID="SetupMTCCurrentState" task="{{mtc_task}}" />
      <Action ID="SetupMTCConnectWithProRRT" acceleration_scale_factor="1.000000" link_padding="0.000000"
              max_iterations="5000" planning_group_name="manipulator" seed="0" task="{{mtc_task}}"
              trajectory_sampling_rate="100" velocity_scale_factor="1.000000" />
      <Action ID="SetupMTCMoveAlongFrameAxis" acceleration_scale="1.000000" axis_frame="grasp_link"
              axis_x="0.000000" axis_y="0.000000" axis_z="1.000000" hand_frame="grasp_link"
              max_distance="0.1" min_distance="0.1" planning_group_name="manipulator" task="{{mtc_task}}"
              velocity_scale="1.000000" ignore_environment_collisions="false" />
      <Action ID="CreatePoseStamped" reference_frame="world" position_xyz="{";".join(map(str, CUBE))}"
              orientation_xyzw="{DOWN}" pose_stamped="{{grasp_pose}}" />
      <Action ID="CreatePoseStamped" reference_frame="world" position_xyz="4.0;3.0;0.8"
              orientation_xyzw="{DOWN}" pose_stamped="{{unreachable}}" />
      <Action ID="ResetPoseStampedVector" vector="{{grasp_pose_vector}}" />
      <Action ID="PushBackVector" input_vector="{{grasp_pose_vector}}" element="{{unreachable}}"
              output_vector="{{grasp_pose_vector}}" />
      <Action ID="PushBackVector" input_vector="{{grasp_pose_vector}}" element="{{grasp_pose}}"
              output_vector="{{grasp_pose_vector}}" />
      <Action ID="SetupMTCBatchPoseIK" end_effector_group="moveit_ee" end_effector_link="grasp_link"
              ik_group="manipulator" ik_timeout_s="0.01" max_ik_solutions="4" monitored_stage="current state"
              target_poses="{{grasp_pose_vector}}" task="{{mtc_task}}" />
      <Action ID="PlanMTCTask" solution="{{mtc_solution}}" task="{{mtc_task}}" />
      <Action ID="ConvertMtcSolutionToJointTrajectory" solution="{{mtc_solution}}"
              joint_trajectory="{{joint_trajectory_msg}}" />
    </Sequence>
  </BehaviorTree>
</root>
"""


@pytest.fixture
def look_at_table(context: BehaviorContext) -> Any:
    """The fake driver reports lab_sim's "Look at Table" waypoint."""
    entry = next(e for e in yaml.safe_load(WAYPOINTS.read_text()) if e["name"] == "Look at Table")
    state = {"name": list(entry["joint_state"]["name"]), "position": list(entry["joint_state"]["position"])}
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        yield dict(zip(state["name"], state["position"], strict=True))


def test_the_pick_and_place_objectives_of_lab_sim_validate(corpus_workspace: Path) -> None:  # noqa: F811
    from kinema.config import ObjectiveLibrary, Workspace, resolve_config
    from kinema.plugins import BehaviorHost
    from kinema.runtime.library_check import file_problem

    resolved = resolve_config(CONFIG, Workspace.discover(corpus_workspace))
    library = ObjectiveLibrary.load(resolved)
    host = BehaviorHost.for_config(resolved)
    host.load().raise_for_errors()
    factory = host.registry.create_factory()
    files = sorted((corpus_workspace / "src" / CONFIG / "objectives").glob("*.xml"))
    problems = {path.stem: file_problem(library, path, factory) for path in files}
    valid = {stem for stem, problem in problems.items() if problem is None}
    missing = sorted((BEFORE | ADDED | TASK_PLANNING) - valid)
    report = "\n".join(f"  {stem}: {problems.get(stem)}" for stem in missing)
    assert not missing, f"{len(valid)} of {len(files)} validate; these required ones do not:\n{report}"
    assert len(valid) >= 41


def test_a_pick_task_plans_to_the_reachable_grasp_and_joins_into_one_trajectory(
    registry: Any, context: BehaviorContext, look_at_table: dict[str, float]
) -> None:
    from kinema.motion import fk

    result = run_objective(PICK_PLAN, registry=registry, context=context, timeout=120.0)
    assert result.status == NodeStatus.SUCCESS, result.toasts
    summary = next(t for t in result.toasts if t.startswith("PlanMTCTask: planned task 'pick_object'"))
    assert "4. batch pose IK: ok" in summary and "FAILED" not in summary, summary
    message = result.blackboard["joint_trajectory_msg"]
    model = context.robot_model
    q = model.configuration(look_at_table)
    first = np.array(message.points[0].positions)
    last = np.array(message.points[-1].positions)
    names = [str(n) for n in message.joint_names]
    np.testing.assert_allclose(first, [look_at_table[n] for n in names], atol=1e-6)
    q[[model.index(n) for n in names]] = last
    assert np.linalg.norm(fk(model, q, "grasp_link")[:3, 3] - CUBE) < 1e-3
    steps = np.abs(np.diff(np.array([p.positions for p in message.points]), axis=0)).max()
    assert steps < 0.05, f"the joined trajectory jumps {steps:.3f} rad between points"


def test_a_failing_stage_fails_planning_naming_it(
    registry: Any, context: BehaviorContext, look_at_table: dict[str, float]
) -> None:
    xml = PICK_PLAN.replace('max_distance="0.1" min_distance="0.1"', 'max_distance="3.0" min_distance="2.5"')
    result = run_objective(xml, registry=registry, context=context, timeout=120.0)
    assert result.status == NodeStatus.FAILURE
    failure = next(t for t in result.toasts if t.startswith("PlanMTCTask: planning failed"))
    assert "('move along frame axis')" in failure and "Cartesian path stopped at" in failure, failure


def test_setup_behaviors_need_a_task_and_valid_values(behavior: Any, context: BehaviorContext) -> None:
    run = tick_behavior(behavior("SetupMTCCurrentState"), {"task": None}, context=context)
    assert run.status == NodeStatus.FAILURE
    assert "needs the task InitializeMTCTask creates" in run.toasts[-1], run.toasts
    task = tick_behavior(behavior("InitializeMTCTask"), {"task_id": "t"}, context=context).outputs["task"]
    run = tick_behavior(
        behavior("SetupMTCMoveAlongFrameAxis"),
        {"task": task, "axis_x": 0.0, "axis_y": 0.0, "axis_z": 0.0},
        context=context,
    )
    assert run.status == NodeStatus.FAILURE and "the axis must be 3 finite numbers" in run.toasts[-1]
    run = tick_behavior(
        behavior("SetupMTCConnectWithProRRT"), {"task": task, "velocity_scale_factor": 1.5}, context=context
    )
    assert run.status == NodeStatus.FAILURE and "velocity scale factor must be in (0, 1]" in run.toasts[-1]
    run = tick_behavior(behavior("ConvertMtcSolutionToJointTrajectory"), {"solution": task}, context=context)
    assert run.status == NodeStatus.FAILURE and "needs a solution PlanMTCTask planned" in run.toasts[-1]


@pytest.mark.parametrize(
    ("behavior_id", "ports", "expected"),
    [
        (
            "SetupMTCConnectWithProRRT",
            {"velocity_scale_factor": 0.5, "link_padding": 0.02, "trajectory_sampling_rate": 50, "seed": 7},
            {"velocity_scale": 0.5, "link_padding": 0.02, "sample_period": 0.02, "seed": 7},
        ),
        (
            "SetupMTCMoveAlongFrameAxis",
            {"velocity_scale": 0.3, "acceleration_scale": 0.4, "planning_group_name": "manipulator"},
            {"velocity_scale": 0.3, "acceleration_scale": 0.4, "link_padding": 0.0},
        ),
        (
            "SetupMTCPlanToRobotState",
            {
                "joint_state": {"robotiq_85_left_knuckle_joint": 0.7},
                "planning_group_name": "gripper",
            },
            {"group": "gripper", "velocity_scale": 1.0, "link_padding": 0.01},
        ),
    ],
)
def test_setup_behaviors_read_their_motion_ports_into_the_stage(
    behavior: Any, context: BehaviorContext, behavior_id: str, ports: dict[str, Any], expected: dict[str, Any]
) -> None:
    task = tick_behavior(behavior("InitializeMTCTask"), {"task_id": "t"}, context=context).outputs["task"]
    run = tick_behavior(behavior(behavior_id), {"task": task, **ports}, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    motion = run.outputs["task"].stages[-1].motion
    assert {key: getattr(motion, key) for key in expected} == pytest.approx(expected)
    if "trajectory_sampling_rate" in ports:
        bad = tick_behavior(
            behavior(behavior_id), {"task": task, "trajectory_sampling_rate": 0}, context=context
        )
        assert (
            bad.status == NodeStatus.FAILURE and "trajectory_sampling_rate must be positive" in bad.toasts[-1]
        )


def test_a_solution_is_replayed_from_where_it_starts_moving_there_first(
    registry: Any, behavior: Any, context: BehaviorContext, look_at_table: dict[str, float]
) -> None:
    result = run_objective(PICK_PLAN, registry=registry, context=context, timeout=120.0)
    assert result.status == NodeStatus.SUCCESS, result.toasts
    pick = result.blackboard["mtc_solution"]
    task = tick_behavior(behavior("InitializeMTCTask"), {"task_id": "replay"}, context=context).outputs[
        "task"
    ]
    run = tick_behavior(behavior("SetupMTCFromSolution"), {"task": task, "solution": pick}, context=context)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    run = tick_behavior(behavior("PlanMTCTask"), {"task": task}, context=context, timeout=60.0)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert run.outputs["solution"].joined().duration == pytest.approx(pick.joined().duration)

    # A solution that starts elsewhere (the robot is at "Look at Table", this one starts at the grasp).
    task = tick_behavior(behavior("InitializeMTCTask"), {"task_id": "retreat"}, context=context).outputs[
        "task"
    ]
    from kinema.motion import CollisionChecker
    from kinema.motion.task import Task, plan_task
    from kinema.motion.task_stages import CurrentState, MotionSettings, MoveAlongFrameAxis

    checker = CollisionChecker(context.robot_model)
    elsewhere = plan_task(
        Task(
            "up",
            [
                CurrentState(pick.end),
                MoveAlongFrameAxis(
                    (0, 0, 1),
                    "world",
                    "grasp_link",
                    0.05,
                    0.05,
                    motion=MotionSettings(group="manipulator", link_padding=0.0),
                ),
            ],
        ),
        checker,
    )
    tick_behavior(behavior("SetupMTCFromSolution"), {"task": task, "solution": elsewhere}, context=context)
    run = tick_behavior(behavior("PlanMTCTask"), {"task": task}, context=context, timeout=60.0)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert any("a collision-free move there comes first" in toast for toast in run.toasts), run.toasts
    replay = run.outputs["solution"]
    # It starts where the robot is, reaches the stored solution's start, then replays it unchanged.
    names = context.robot_model.joint_names
    at_table = np.array([look_at_table.get(n, 0.0) for n in names])
    arm = [names.index(n) for n in look_at_table if n in names and n != "robotiq_85_left_knuckle_joint"]
    assert np.abs(replay.start[arm] - at_table[arm]).max() < 1e-3
    assert np.abs(replay.end - elsewhere.end).max() < 1e-6
    assert replay.joined().duration > elsewhere.joined().duration


def test_a_planned_task_is_drawn_in_the_view_stage_by_stage(
    registry: Any, context: BehaviorContext, node: Any, look_at_table: dict[str, float]
) -> None:
    import threading

    arrays: list[Any] = []
    got = threading.Event()

    def keep(message: Any) -> None:
        arrays.append(message)
        got.set()

    node.create_subscription("visualization_msgs/msg/MarkerArray", "/visualization_marker_array", keep)
    result = run_objective(PICK_PLAN, registry=registry, context=context, timeout=120.0)
    assert result.status == NodeStatus.SUCCESS, result.toasts
    assert got.wait(10.0), "no MarkerArray published"
    lines = [m for a in arrays for m in a.markers if m.ns == "mtc_solution" and m.type == 4 and m.action == 0]
    assert [m.text for m in lines] == ["connect", "move along frame axis"], [m.text for m in lines]
    end = lines[-1].points[-1]
    assert np.linalg.norm(np.array([end.x, end.y, end.z]) - CUBE) < 1e-3
