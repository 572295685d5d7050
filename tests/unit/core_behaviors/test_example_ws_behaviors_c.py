"""Task-planning behaviors and ports of MoveIt Pro's example workspace, offline on lab_sim.

SplitMTCSolution and SetupMTCCartesianMoveToRobotState ("Push Button" and "Retreat To Initial Pose"),
SetupMTCPlanToPose's orientation_constraint, LoadImageFromFile's frame_id ("Automask from File") and
BreakpointSubscriber's message (space_satellite_sim's grapple objective).
"""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.resources import bundled_dir
from kinema.testing import publish_repeatedly, run_objective, tick_behavior

WAYPOINTS = bundled_dir("configs") / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml"
APPROACH_OFFSET = (0.1, 0.05, -0.15)  # m, world: from grasp_link at "Look at Table" to the approach pose
CONSTRAINT = "[{link_name: grasp_link, angle_tolerance: 0.2}]"  # as lab_sim's constrained pick and place


def _look_at_table() -> dict[str, float]:
    entry = next(e for e in yaml.safe_load(WAYPOINTS.read_text()) if e["name"] == "Look at Table")
    return dict(zip(entry["joint_state"]["name"], entry["joint_state"]["position"], strict=True))


@pytest.fixture
def look_at_table(context: BehaviorContext) -> Any:
    """The fake driver reports lab_sim's "Look at Table" waypoint."""
    state = _look_at_table()
    message = {"name": list(state), "position": list(state.values())}
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", message):
        yield state


def _manipulator(**overrides: Any) -> Any:
    from kinema.motion.task_stages import MotionSettings

    return MotionSettings(group="manipulator", **overrides)


def _approach_pose(model: Any, q: np.ndarray, turn: float = 0.0) -> np.ndarray:
    """grasp_link at "Look at Table" moved by APPROACH_OFFSET and turned ``turn`` rad about world z."""
    from kinema.motion import fk
    from kinema.transforms import rotation_from_rotvec

    pose = fk(model, q, "grasp_link")
    pose[:3, 3] += APPROACH_OFFSET
    pose[:3, :3] = rotation_from_rotvec([0.0, 0.0, turn]) @ pose[:3, :3]
    return pose


def _push_stages(model: Any, q: np.ndarray, allow_rules: bool = False) -> list[Any]:
    """MoveIt Pro's "Push Button" task (or "Push Button ML"'s, with its collision rules)."""
    from kinema.motion.task_stages import AllowCollisions, CurrentState, MoveAlongFrameAxis, PlanToPose

    push = MoveAlongFrameAxis(
        (0, 0, 1), "grasp_link", "grasp_link", 0.05, 0.1, _manipulator(link_padding=0.0), name="push"
    )
    stages: list[Any] = [
        CurrentState(q),
        PlanToPose(("world", _approach_pose(model, q)), "grasp_link", _manipulator()),
    ]
    if allow_rules:
        return [
            *stages,
            AllowCollisions(["gripper"], ["<octomap>"], True),
            push,
            AllowCollisions(["gripper"], ["<octomap>"], False, name="forbid collisions"),
        ]
    return [*stages, push]


def _plan(model: Any, stages: list[Any]) -> Any:
    from kinema.motion import CollisionChecker
    from kinema.motion.task import Task, plan_task

    return plan_task(Task("push_button", stages), CollisionChecker(model))


def _positions(solution: Any) -> np.ndarray:
    return np.asarray(solution.joined().positions)


def _tool_points(model: Any, solution: Any, frame: str = "grasp_link") -> np.ndarray:
    return np.concatenate([points for _stage, points in solution.tool_paths(model, frame)])


def _worst_turn(model: Any, solution: Any, link: str = "grasp_link") -> float:
    """The largest angle (rad) ``link`` turns from its start orientation along the solution."""
    from kinema.motion import fk
    from kinema.transforms import rotation_angle

    index = {n: i for i, n in enumerate(solution.joint_names)}
    q = solution.start.copy()
    start = fk(model, q, link)[:3, :3]
    worst = 0.0
    for sub in solution.sub_trajectories:
        cols = [index[n] for n in sub.trajectory.joint_names]
        for row in sub.trajectory.positions:
            q[cols] = row
            worst = max(worst, rotation_angle(start, fk(model, q, link)[:3, :3]))
    return worst


# ------------------------------------------------------------------------------------ SplitMTCSolution
@pytest.mark.parametrize("allow_rules", [False, True], ids=["push_button", "push_button_ml"])
def test_split_at_3_gives_the_move_to_the_button_and_the_push_which_together_are_the_whole(
    lab_sim_model: Any, allow_rules: bool
) -> None:
    from kinema.motion.solution_split import split_solution

    model = lab_sim_model
    whole = _plan(model, _push_stages(model, model.configuration(_look_at_table()), allow_rules))
    first, second = split_solution(whole, 3)
    assert [s.stage for s in first.sub_trajectories] == ["plan to pose"]
    assert [s.stage for s in second.sub_trajectories] == ["push"]
    # Push Button ML's collision rules around the push go with it.
    assert [c.stage for c in second.scene_changes] == (
        ["allow collisions", "forbid collisions"] if allow_rules else []
    )
    assert [(c.stage, c.before) for c in second.scene_changes] == (
        [("allow collisions", 0), ("forbid collisions", 1)] if allow_rules else []
    )
    assert not first.scene_changes
    np.testing.assert_array_equal(first.start, whole.start)
    np.testing.assert_array_equal(second.start, first.end)
    np.testing.assert_allclose(second.end, whole.end, atol=1e-12)
    # Run one after the other, the halves are the whole motion.
    together = np.vstack([_positions(first), _positions(second)[1:]])
    np.testing.assert_allclose(together, _positions(whole), atol=1e-12)
    assert first.joined().duration + second.joined().duration == pytest.approx(whole.joined().duration)


@pytest.mark.parametrize("index", [0, 4, -1])
def test_split_mtc_solution_refuses_an_index_that_leaves_a_half_empty_naming_the_range(
    behavior: Any, context: BehaviorContext, lab_sim_model: Any, index: int
) -> None:
    whole = _plan(lab_sim_model, _push_stages(lab_sim_model, lab_sim_model.configuration(_look_at_table())))
    run = tick_behavior(behavior("SplitMTCSolution"), {"solution_in": whole, "index": index}, context=context)
    assert run.status == NodeStatus.FAILURE
    assert f"index {index} is out of range" in run.toasts[-1], run.toasts
    assert "valid indices (both halves non-empty): 1 to 3" in run.toasts[-1]
    assert "0: current state, 1: plan to pose, 2: plan to pose: IK, 3: push" in run.toasts[-1]
    run = tick_behavior(behavior("SplitMTCSolution"), {"solution_in": "plan", "index": 1}, context=context)
    assert run.status == NodeStatus.FAILURE and "needs a solution PlanMTCTask planned" in run.toasts[-1]


# ------------------------------------------------------------------- SetupMTCCartesianMoveToRobotState
def test_the_cartesian_move_ends_at_the_joint_state_along_a_straight_tip_line(
    behavior: Any, context: BehaviorContext, lab_sim_model: Any
) -> None:
    from kinema.motion import fk
    from kinema.motion.task_stages import CartesianMoveToJointState, CurrentState, PlanToJointState

    model = lab_sim_model
    whole = _plan(model, _push_stages(model, model.configuration(_look_at_table())))
    # The state saved before the push, as a full robot state (the gripper too, as SaveCurrentState's).
    saved = {"name": list(model.joint_names), "position": [float(v) for v in whole.start]}
    from kinema.motion.solution_split import split_solution

    approach = split_solution(whole, 3)[0].end
    saved["position"] = [float(v) for v in approach]
    task = tick_behavior(behavior("InitializeMTCTask"), {"task_id": "retreat"}, context=context).outputs[
        "task"
    ]
    run = tick_behavior(
        behavior("SetupMTCCartesianMoveToRobotState"),
        {"task": task, "joint_state": saved, "planning_group_name": "manipulator"},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    stage = run.outputs["task"].stages[-1]
    assert isinstance(stage, CartesianMoveToJointState)
    assert stage.motion.group == "manipulator" and stage.motion.link_padding == 0.0

    retreat = _plan(model, [CurrentState(whole.end), stage])
    group = [model.index(n) for n in model.group("manipulator").joint_names]
    np.testing.assert_allclose(retreat.end[group], approach[group], atol=1e-9)
    points = _tool_points(model, retreat)
    line = points[-1] - points[0]
    assert np.linalg.norm(line) > 0.05
    along = (points - points[0]) @ (line / np.linalg.norm(line))
    off_line = np.linalg.norm(points - points[0] - np.outer(along, line / np.linalg.norm(line)), axis=1)
    assert off_line.max() < 1e-3, f"the tip leaves the straight line by {off_line.max():.4f} m"
    np.testing.assert_allclose(points[-1], fk(model, approach, "grasp_link")[:3, 3], atol=1e-6)
    # A joint-space move to the same state does not keep the tip on the line: the stage is what does.
    arm = {n: v for n, v in stage.goal.items() if n in model.group("manipulator").joint_names}
    free = _plan(model, [CurrentState(whole.end), PlanToJointState(arm, _manipulator())])
    free_points = _tool_points(model, free)
    free_along = (free_points - free_points[0]) @ (line / np.linalg.norm(line))
    free_off = free_points - free_points[0] - np.outer(free_along, line / np.linalg.norm(line))
    assert np.linalg.norm(free_off, axis=1).max() > 10 * off_line.max()


# ------------------------------------------------------------------ SetupMTCPlanToPose orientation_constraint
def test_orientation_constraint_is_read_from_the_example_yaml_and_bad_values_name_the_port(
    behavior: Any, context: BehaviorContext
) -> None:
    from kinema.motion.task_stages import OrientationConstraint
    from kinema.transport import from_dict

    pose = from_dict("geometry_msgs/msg/PoseStamped", {"header": {"frame_id": "world"}})
    task = tick_behavior(behavior("InitializeMTCTask"), {"task_id": "t"}, context=context).outputs["task"]
    setup = behavior("SetupMTCPlanToPose")
    run = tick_behavior(
        setup, {"task": task, "target_pose": pose, "orientation_constraint": CONSTRAINT}, context=context
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert list(run.outputs["task"].stages[-1].orientation_constraints) == [
        OrientationConstraint("grasp_link", 0.2)
    ]
    for empty in ("[]", ""):
        run = tick_behavior(
            setup, {"task": task, "target_pose": pose, "orientation_constraint": empty}, context=context
        )
        assert run.status == NodeStatus.SUCCESS and not run.outputs["task"].stages[-1].orientation_constraints
    for bad, says in (
        ("[{angle_tolerance: 0.2}]", "entry 0 names no link_name"),
        ("[{link_name: grasp_link, angle_tolerance: -1}]", "angle_tolerance must be a non-negative angle"),
        ("grasp_link", "must be a list like"),
    ):
        run = tick_behavior(
            setup, {"task": task, "target_pose": pose, "orientation_constraint": bad}, context=context
        )
        assert run.status == NodeStatus.FAILURE and says in run.toasts[-1], (bad, run.toasts)


def test_an_orientation_constraint_refuses_a_target_turned_beyond_its_tolerance(lab_sim_model: Any) -> None:
    from kinema.motion.task import TaskPlanningError
    from kinema.motion.task_stages import CurrentState, OrientationConstraint, PlanToPose

    model = lab_sim_model
    q = model.configuration(_look_at_table())
    turned = PlanToPose(("world", _approach_pose(model, q, turn=0.5)), "grasp_link", _manipulator())
    assert _worst_turn(model, _plan(model, [CurrentState(q), turned])) > 0.45
    kept = PlanToPose(
        ("world", _approach_pose(model, q, turn=0.5)),
        "grasp_link",
        _manipulator(),
        orientation_constraints=[OrientationConstraint("grasp_link", 0.2)],
    )
    with pytest.raises(TaskPlanningError, match=r"turns grasp_link 0\.500 rad .* constraint's 0\.200 rad"):
        _plan(model, [CurrentState(q), kept])
    within = PlanToPose(
        ("world", _approach_pose(model, q, turn=0.15)),
        "grasp_link",
        _manipulator(),
        orientation_constraints=[OrientationConstraint("tool0", 0.2)],
    )
    assert _worst_turn(model, _plan(model, [CurrentState(q), within]), "tool0") <= 0.2 + 1e-6


def test_a_free_motion_that_turns_the_link_too_far_is_replaced_by_one_that_keeps_it(
    lab_sim_model: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The free search may wander (an RRT around an obstacle); here it twists the wrist on its way."""
    import kinema.motion.planner as planner
    from kinema.motion.task_stages import CurrentState, OrientationConstraint, PlanToPose
    from kinema.motion.trajectory import JointPath

    real = planner.plan_joint_goal

    def wandering(*args: Any, **kwargs: Any) -> JointPath:
        path = real(*args, **kwargs)
        middle = (path.positions[0] + path.positions[-1]) / 2
        middle[list(path.joint_names).index("wrist_3_joint")] += 0.8
        return JointPath(path.joint_names, np.vstack([path.positions[0], middle, path.positions[-1]]))

    monkeypatch.setattr(planner, "plan_joint_goal", wandering)
    model = lab_sim_model
    q = model.configuration(_look_at_table())
    target = _approach_pose(model, q)

    def stage(constraints: list[Any]) -> Any:
        return PlanToPose(
            ("world", target), "grasp_link", _manipulator(), orientation_constraints=constraints
        )

    free = _plan(model, [CurrentState(q), stage([])])
    kept = _plan(model, [CurrentState(q), stage([OrientationConstraint("grasp_link", 0.2)])])
    assert _worst_turn(model, free) > 0.5
    assert _worst_turn(model, kept) <= 0.2 + 1e-6
    from kinema.motion import fk

    np.testing.assert_allclose(fk(model, kept.end, "grasp_link"), target, atol=1e-4)


# --------------------------------------------------------------------------- LoadImageFromFile frame_id
def test_load_image_from_file_stamps_the_frame_id(
    behavior: Any, node: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from PIL import Image

    monkeypatch.chdir(tmp_path)
    Image.new("RGB", (3, 2), (10, 20, 30)).save(tmp_path / "coffee_cup1.png")
    offline = BehaviorContext(node)
    stamped = tick_behavior(
        behavior("LoadImageFromFile"), {"file_path": "coffee_cup1.png", "frame_id": "camera"}, context=offline
    )
    assert stamped.status == NodeStatus.SUCCESS, stamped.toasts
    assert stamped.outputs["image"].header.frame_id == "camera"
    plain = tick_behavior(behavior("LoadImageFromFile"), {"file_path": "coffee_cup1.png"}, context=offline)
    assert plain.outputs["image"].header.frame_id == ""


# ------------------------------------------------------------------------ BreakpointSubscriber message
def test_the_breakpoint_asks_the_user_its_message(
    behavior: Any, context: BehaviorContext, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("KINEMA_AUTO_APPROVE", raising=False)
    prompts: list[str] = []
    answered = threading.Event()

    def answer(request: Any) -> dict[str, Any]:
        prompts.append(str(request.prompt))
        answered.set()
        return {"approved": True, "message": ""}

    context.node.create_service("kinema_msgs/srv/RequestApproval", "/kinema/user_approval", answer)
    breakpoint_subscriber = behavior("BreakpointSubscriber")
    run = tick_behavior(
        breakpoint_subscriber, {"message": "Approve satellite grappling"}, context=context, timeout=10.0
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    run = tick_behavior(breakpoint_subscriber, {}, context=context, timeout=10.0)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert prompts[0].startswith("Approve satellite grappling (breakpoint at "), prompts
    assert prompts[1].endswith(": resume?") and "satellite" not in prompts[1], prompts


# ------------------------------------------------------------ the example objectives' ports, in one tree
def _objective(image: Path, approach_xyzw: str, approach_xyz: str) -> str:
    return f"""
<root BTCPP_format="4" main_tree_to_execute="push and retreat">
  <BehaviorTree ID="push and retreat">
    <Sequence>
      <Action ID="LoadImageFromFile" frame_id="camera" image="{{image}}" file_path="{image}" />
      <Action ID="InitializeMTCTask" task_id="push_button" task="{{push_button_task}}" />
      <Action ID="SetupMTCCurrentState" task="{{push_button_task}}" />
      <Action ID="CreatePoseStamped" reference_frame="world" position_xyz="{approach_xyz}"
              orientation_xyzw="{approach_xyzw}" pose_stamped="{{target_pose}}" />
      <Action ID="SetupMTCPlanToPose" acceleration_scale_factor="1.000000" ik_frame="grasp_link"
              orientation_constraint="{CONSTRAINT}" link_padding="0.01" max_iterations="50000"
              monitored_stage="current state" planning_group_name="manipulator" target_pose="{{target_pose}}"
              trajectory_sampling_rate="100" velocity_scale_factor="1.000000" task="{{push_button_task}}" />
      <Action ID="SetupMTCMoveAlongFrameAxis" task="{{push_button_task}}" hand_frame="grasp_link"
              axis_frame="grasp_link" axis_x="0.0" axis_y="0.0" axis_z="1.0" max_distance="0.1"
              min_distance="0.05" planning_group_name="manipulator" velocity_scale="0.05"
              acceleration_scale="0.05" />
      <Action ID="PlanMTCTask" solution="{{full_push_button_solution}}" task="{{push_button_task}}" />
      <Action ID="SplitMTCSolution" solution_in="{{full_push_button_solution}}" index="3"
              solution_out_1="{{move_to_approach_solution}}" solution_out_2="{{push_solution}}" />
      <Action ID="BreakpointSubscriber" breakpoint_topic="/moveit_pro_breakpoint"
              message="Approve satellite grappling" />
      <Action ID="ConvertMtcSolutionToJointTrajectory" solution="{{move_to_approach_solution}}"
              joint_trajectory="{{approach_trajectory}}" />
      <Action ID="GetRobotStateFromTrajectory" joint_trajectory_msg="{{approach_trajectory}}"
              from_start="false" time_from_reference="0" joint_state="{{pre_approach_robot_state}}" />
      <Action ID="ConvertMtcSolutionToJointTrajectory" solution="{{push_solution}}"
              joint_trajectory="{{push_trajectory}}" />
      <Action ID="InitializeMTCTask" task_id="close_cabinet_door_retreat" task="{{retreat_task}}" />
      <Action ID="SetupMTCFromSolution" solution="{{full_push_button_solution}}" task="{{retreat_task}}" />
      <Action ID="SetupMTCCartesianMoveToRobotState" joint_state="{{pre_approach_robot_state}}"
              planning_group_name="manipulator" task="{{retreat_task}}" />
      <Action ID="PlanMTCTask" solution="{{return_to_initial_waypoint_solution}}" task="{{retreat_task}}" />
    </Sequence>
  </BehaviorTree>
</root>
"""


def test_an_objective_with_the_example_objectives_ports_pushes_and_retreats(
    registry: Any,
    context: BehaviorContext,
    look_at_table: dict[str, float],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import platformdirs
    from PIL import Image

    from kinema.motion import fk
    from kinema.transforms import quaternion_from_matrix

    monkeypatch.setenv("KINEMA_AUTO_APPROVE", "1")
    # Objectives read files in the workspace, the config packages or Kinema's data folder (per test).
    folder = platformdirs.user_data_path("kinema")
    folder.mkdir(parents=True, exist_ok=True)
    Image.new("RGB", (4, 3), (200, 120, 40)).save(folder / "coffee_cup1.png")
    model = context.robot_model
    approach = _approach_pose(model, model.configuration(look_at_table))
    xyzw = ";".join(f"{v:.9f}" for v in quaternion_from_matrix(approach[:3, :3]))
    xyz = ";".join(f"{v:.9f}" for v in approach[:3, 3])
    result = run_objective(
        _objective(folder / "coffee_cup1.png", xyzw, xyz), registry=registry, context=context, timeout=120.0
    )
    assert result.status == NodeStatus.SUCCESS, result.toasts
    board = result.blackboard
    assert board["image"].header.frame_id == "camera"
    assert any("Approve satellite grappling" in toast for toast in result.toasts), result.toasts
    whole = board["full_push_button_solution"]
    approach_part, push = board["move_to_approach_solution"], board["push_solution"]
    assert [s.stage for s in push.sub_trajectories] == ["move along frame axis"]
    assert len(board["approach_trajectory"].points) + len(board["push_trajectory"].points) - 1 == len(
        whole.joined().times
    )
    np.testing.assert_allclose(fk(model, approach_part.end, "grasp_link"), approach, atol=1e-3)
    # The retreat replays the push, then comes back along a straight line to the pre-approach state.
    retreat = board["return_to_initial_waypoint_solution"]
    group = [model.index(n) for n in model.group("manipulator").joint_names]
    np.testing.assert_allclose(retreat.end[group], approach_part.end[group], atol=1e-4)
    back = retreat.tool_paths(model, "grasp_link")[-1][1]
    assert retreat.sub_trajectories[-1].stage == "cartesian move to joint state"
    line = (back[-1] - back[0]) / np.linalg.norm(back[-1] - back[0])
    off = back - back[0] - np.outer((back - back[0]) @ line, line)
    assert np.linalg.norm(off, axis=1).max() < 1e-3


def test_a_saved_robot_state_with_the_gripper_and_its_mimic_fingers_is_a_goal_for_the_arm(
    lab_sim_model: Any,
) -> None:
    """SaveCurrentState saves every /joint_states joint, a gripper's mimic fingers too; the stages that move
    back to it (PickNik's push_button and retreat_to_initial_pose) failed on them ("unknown joint
    'robotiq_85_left_finger_joint'", "not in planning group"). The arm's joints are the goal, the rest
    stay."""
    from kinema.errors import MotionError
    from kinema.motion.task_stages import CartesianMoveToJointState, CurrentState, PlanToJointState

    model = lab_sim_model
    start = model.configuration(_look_at_table())
    whole = _plan(model, _push_stages(model, start))
    from kinema.motion.solution_split import split_solution

    approach = split_solution(whole, 3)[0].end
    saved = {name: float(approach[model.index(name)]) for name in model.joint_names}
    saved.update({follower: 0.0 for follower in model.mimics})  # as /joint_states lists them
    assert set(model.mimics) and not set(model.mimics) & set(model.joint_names)
    arm = [model.index(n) for n in model.group("manipulator").joint_names]
    for stage in (
        CartesianMoveToJointState(saved, _manipulator(link_padding=0.0)),
        PlanToJointState(saved, _manipulator()),
    ):
        back = _plan(model, [CurrentState(whole.end), stage])
        np.testing.assert_allclose(back.end[arm], approach[arm], atol=1e-6)
    with pytest.raises(MotionError, match="unknown joint 'no_such_joint'"):
        typo = PlanToJointState({**saved, "no_such_joint": 0.0}, _manipulator())
        _plan(model, [CurrentState(whole.end), typo])
