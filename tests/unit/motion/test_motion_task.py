"""The task planner: MTC-style stages planned into one timed solution on lab_sim's robot and scene."""

from __future__ import annotations

import re
from collections.abc import Callable

import numpy as np
import pytest

from kinema.motion import CollisionChecker, RobotModel, fk
from kinema.motion.planning_scene import CollisionObject
from kinema.motion.task import Task, TaskPlanningError, TaskSolution, plan_task
from kinema.motion.task_stages import (
    AllowCollisions,
    BatchPoseIK,
    Connect,
    CurrentState,
    FromSolution,
    MotionSettings,
    MoveAlongFrameAxis,
    PlanToJointState,
    PlanToPose,
)

CUBE = np.array([-0.3, 0.62, 0.504])  # lab_sim's cube, where the gripper grasps it


@pytest.fixture
def start(waypoint_q: Callable[[str], np.ndarray]) -> np.ndarray:
    return waypoint_q("Look at Table")


@pytest.fixture
def grasp(model: RobotModel, waypoint_q: Callable[[str], np.ndarray]) -> np.ndarray:
    """A top-down grasp of the cube (the pick waypoint's gripper orientation)."""
    pose = np.eye(4)
    pose[:3, :3] = fk(model, waypoint_q("3 Waypoint Pick Pose"), "grasp_link")[:3, :3]
    pose[:3, 3] = CUBE
    return pose


def pick_task(
    start: np.ndarray, poses: list[np.ndarray], velocity_scale: float = 1.0, acceleration_scale: float = 1.0
) -> Task:
    return Task(
        "pick",
        [
            CurrentState(start),
            Connect(
                MotionSettings(
                    link_padding=0.0,
                    velocity_scale=velocity_scale,
                    acceleration_scale=acceleration_scale,
                    group="manipulator",
                )
            ),
            MoveAlongFrameAxis(
                (0, 0, 1),
                "grasp_link",
                "grasp_link",
                0.1,
                0.1,
                MotionSettings(link_padding=0.0, group="manipulator"),
                name="approach",
            ),
            BatchPoseIK(
                [("world", p) for p in poses], "grasp_link", name="grasp pose IK", group="manipulator"
            ),
        ],
    )


def tool_path(model: RobotModel, solution: TaskSolution, stage: str, frame: str) -> np.ndarray:
    sub = next(s for s in solution.sub_trajectories if s.stage == stage)
    q = solution.start.copy()
    idx = [model.index(n) for n in sub.trajectory.joint_names]
    out = []
    for row in sub.trajectory.positions:
        q[idx] = row
        out.append(fk(model, q, frame)[:3, 3])
    return np.array(out)


def test_a_pick_task_approaches_the_grasp_in_a_straight_line_and_ends_there(
    model: RobotModel, checker: CollisionChecker, start: np.ndarray, grasp: np.ndarray
) -> None:
    solution = plan_task(pick_task(start, [grasp]), checker)
    assert [s.stage for s in solution.sub_trajectories] == ["connect", "approach"]
    assert [r.status for r in solution.reports] == ["solved"] * 4, solution.reports
    end = fk(model, solution.end, "grasp_link")
    assert np.linalg.norm(end[:3, 3] - CUBE) < 1e-3, end[:3, 3]
    # The approach: 10 cm along the grasp's z axis, on a straight line.
    path = tool_path(model, solution, "approach", "grasp_link")
    z = grasp[:3, 2]
    assert np.linalg.norm(path[0] - (CUBE - 0.1 * z)) < 2e-3, path[0]
    off_line = np.linalg.norm(np.cross(path - CUBE, z), axis=1)
    assert off_line.max() < 2e-3, f"the approach leaves its line by {off_line.max():.4f} m"
    # Joined without jumps: the arm's joints move at most a few centiradians between 10 ms samples.
    joined = solution.joined()
    assert np.abs(np.diff(joined.positions, axis=0)).max() < 0.05
    assert np.allclose(joined.positions[0], solution.start[[model.index(n) for n in joined.joint_names]])
    assert np.allclose(joined.velocities[[0, -1]], 0.0)
    assert joined.duration == pytest.approx(sum(s.trajectory.duration for s in solution.sub_trajectories))
    # The planning scene (lab_sim's table) is honoured all along.
    full = np.repeat(solution.start[None, :], len(joined.times), axis=0)
    full[:, [model.index(n) for n in joined.joint_names]] = joined.positions
    checker.padding = 0.0
    assert checker.first_invalid(full, 0.01) is None


def test_velocity_and_acceleration_scaling_slow_the_stage_they_are_set_on(
    checker: CollisionChecker, start: np.ndarray, grasp: np.ndarray
) -> None:
    fast = plan_task(pick_task(start, [grasp]), checker)
    slow = plan_task(pick_task(start, [grasp], velocity_scale=0.25), checker)
    assert slow.sub_trajectories[0].trajectory.duration > 1.5 * fast.sub_trajectories[0].trajectory.duration
    assert slow.sub_trajectories[1].trajectory.duration == pytest.approx(
        fast.sub_trajectories[1].trajectory.duration, rel=0.05
    )
    gentle = plan_task(pick_task(start, [grasp], acceleration_scale=0.05), checker)
    fast_connect, gentle_connect = fast.sub_trajectories[0].trajectory, gentle.sub_trajectories[0].trajectory
    assert gentle_connect.duration > 1.5 * fast_connect.duration
    assert np.abs(gentle_connect.accelerations).max() < 0.5 * np.abs(fast_connect.accelerations).max()


def test_batch_pose_ik_takes_the_reachable_pose_closest_to_the_state_before(
    model: RobotModel, checker: CollisionChecker, start: np.ndarray, grasp: np.ndarray
) -> None:
    unreachable = grasp.copy()
    unreachable[:3, 3] = [4.0, 3.0, 0.8]
    farther = grasp.copy()
    farther[:3, 3] = CUBE + np.array([0.25, 0.0, 0.0])
    solution = plan_task(pick_task(start, [unreachable, farther, grasp]), checker)
    near = fk(model, solution.end, "grasp_link")[:3, 3]
    distances = {}
    for label, pose in (("cube", grasp), ("farther", farther)):
        only = plan_task(pick_task(start, [pose]), checker)
        distances[label] = float(np.linalg.norm(only.end - start))
    expected = CUBE if distances["cube"] <= distances["farther"] else farther[:3, 3]
    assert np.linalg.norm(near - expected) < 1e-3, (near, distances)

    with pytest.raises(TaskPlanningError) as failure:
        plan_task(pick_task(start, [unreachable, unreachable]), checker)
    message = str(failure.value)
    assert (
        "stage 4 of 4 ('grasp pose IK')" in message and "pose 1 of 2" in message and "pose 2 of 2" in message
    )
    assert [r.status for r in failure.value.reports] == ["solved", "waiting", "waiting", "failed"]


def test_progress_reports_each_stage_waiting_planning_then_solved_or_failed(
    checker: CollisionChecker, start: np.ndarray, grasp: np.ndarray
) -> None:
    seen: list[tuple[tuple[str, str, float, str], ...]] = []

    def keep(reports: tuple) -> None:  # type: ignore[type-arg]
        seen.append(tuple((r.name, r.status, r.seconds, r.comment) for r in reports))

    solution = plan_task(pick_task(start, [grasp]), checker, progress=keep)
    names = ["current state", "connect", "approach", "grasp pose IK"]
    assert [s[0] for s in seen[0]] == names
    assert seen[0][-1][1] == "waiting", seen[0]  # the IK stage waits while the start is read
    for i, name in enumerate(names):
        states = [snapshot[i][1] for snapshot in seen]
        # Each stage is waiting until it is planned, then planning, then solved for good.
        first_planning = states.index("planning")
        assert set(states[:first_planning]) <= {"waiting"}, (name, states)
        assert states[-1] == "solved" and "failed" not in states, (name, states)
    assert [r.stage_type for r in solution.reports] == [
        "CurrentState",
        "Connect",
        "MoveAlongFrameAxis",
        "BatchPoseIK",
    ]
    connect = solution.reports[1]
    assert connect.seconds > 0 and sum(r.seconds for r in solution.reports) <= solution.planning_seconds

    unreachable = grasp.copy()
    unreachable[:3, 3] = [4.0, 3.0, 0.8]
    seen.clear()
    with pytest.raises(TaskPlanningError) as failure:
        plan_task(pick_task(start, [unreachable, unreachable]), checker, progress=keep)
    last = {name: (status, comment) for name, status, _, comment in seen[-1]}
    assert last["grasp pose IK"][0] == "failed" and "pose 2 of 2" in last["grasp pose IK"][1], last
    assert last["connect"][0] == "waiting" and last["approach"][0] == "waiting", last
    assert [r.status for r in failure.value.reports] == [s[1] for s in seen[-1]]


def test_moving_along_a_frame_axis_fails_below_min_distance_with_the_share_reached(
    checker: CollisionChecker, start: np.ndarray, model: RobotModel
) -> None:
    task = Task(
        "reach",
        [
            CurrentState(start),
            MoveAlongFrameAxis(
                (1, 0, 0),
                "world",
                "tool0",
                2.5,
                3.0,
                motion=MotionSettings(group="manipulator", link_padding=0.0),
            ),
        ],
    )
    with pytest.raises(TaskPlanningError) as failure:
        plan_task(task, checker)
    message = str(failure.value)
    assert "stage 2 of 2 ('move along frame axis')" in message and "Cartesian path stopped at" in message
    assert "%" in message and "at least 2.500 m needed" in message
    # With a lower minimum the same stage succeeds and goes as far as it can.
    partial = plan_task(
        Task(
            "reach",
            [
                CurrentState(start),
                MoveAlongFrameAxis(
                    (1, 0, 0),
                    "world",
                    "tool0",
                    0.05,
                    3.0,
                    motion=MotionSettings(group="manipulator", link_padding=0.0),
                ),
            ],
        ),
        checker,
    )
    moved = fk(model, partial.end, "tool0")[:3, 3] - fk(model, start, "tool0")[:3, 3]
    assert 0.05 <= moved[0] < 3.0 and abs(moved[1]) < 1e-3 and abs(moved[2]) < 1e-3, moved


def test_a_square_of_moves_along_world_axes_closes(
    model: RobotModel, checker: CollisionChecker, start: np.ndarray
) -> None:
    sides = [(0, 1, 0), (1, 0, 0), (0, -1, 0), (-1, 0, 0)]
    task = Task(
        "square",
        [
            CurrentState(start),
            *(
                MoveAlongFrameAxis(
                    a,
                    "world",
                    "tool0",
                    0.2,
                    0.2,
                    motion=MotionSettings(group="manipulator", link_padding=0.0),
                )
                for a in sides
            ),
        ],
    )
    solution = plan_task(task, checker)
    origin = fk(model, start, "tool0")[:3, 3]
    # Stage names repeat: read each sub-trajectory's corner in order.
    q = start.copy()
    corners = []
    for sub in solution.sub_trajectories:
        q[[model.index(n) for n in sub.trajectory.joint_names]] = sub.trajectory.positions[-1]
        corners.append(fk(model, q, "tool0")[:3, 3] - origin)
    expected = np.array([[0, 0.2, 0], [0.2, 0.2, 0], [0.2, 0, 0], [0, 0, 0]])
    assert np.abs(np.array(corners) - expected).max() < 1e-3, np.round(corners, 4)


def test_plan_to_pose_and_to_joint_state_go_forwards_and_a_pose_inside_an_obstacle_fails(
    model: RobotModel, checker: CollisionChecker, start: np.ndarray, grasp: np.ndarray, arm_goal
) -> None:
    above = grasp.copy()
    above[:3, 3] = CUBE + np.array([0.0, 0.0, 0.15])
    home = arm_goal("Home")
    task = Task(
        "moves",
        [
            CurrentState(start),
            PlanToPose(("world", above), "grasp_link", motion=MotionSettings(group="manipulator")),
            PlanToJointState(home, motion=MotionSettings(group="manipulator")),
        ],
    )
    solution = plan_task(task, checker)
    q = start.copy()
    first = solution.sub_trajectories[0].trajectory
    q[[model.index(n) for n in first.joint_names]] = first.positions[-1]
    assert np.linalg.norm(fk(model, q, "grasp_link")[:3, 3] - above[:3, 3]) < 1e-3
    for name, value in home.items():
        assert solution.end[model.index(name)] == pytest.approx(value, abs=1e-6)

    # A box added to the planning scene around the target: no collision-free IK solution there.
    checker.scene.add(CollisionObject("wall", "box", (0.02, 0.3, 0.3), _at(-0.3, 0.62, 0.924)))
    with pytest.raises(TaskPlanningError) as failure:
        plan_task(
            Task(
                "into the wall",
                [
                    CurrentState(start),
                    PlanToPose(
                        ("world", _at(-0.3, 0.62, 0.924, grasp)),
                        "grasp_link",
                        motion=MotionSettings(group="manipulator"),
                    ),
                ],
            ),
            checker,
        )
    assert "stage 2 of 2 ('plan to pose')" in str(failure.value) and "no IK solution" in str(failure.value)


def test_a_connect_with_no_way_through_fails_naming_it_after_its_planning_time(
    model: RobotModel, checker: CollisionChecker, waypoint_q: Callable[[str], np.ndarray]
) -> None:
    """A wall across the rail (above its pedestal, everywhere else) parts two states of the carriage."""
    home = waypoint_q("Home")
    rail = model.index("linear_rail_joint")
    here, there = home.copy(), home.copy()
    here[rail], there[rail] = model.lower[rail] + 0.1, model.upper[rail] - 0.1
    a, b = fk(model, here, "base_link")[:3, 3], fk(model, there, "base_link")[:3, 3]
    along = (b - a) / np.linalg.norm(b - a)  # the rail's direction in the world, whichever it is
    pedestal_top = fk(model, here, "linear_rail_carriage_link")[2, 3]
    wall = np.eye(4)
    wall[:3, :3] = np.column_stack([along, np.cross([0.0, 0.0, 1.0], along), [0.0, 0.0, 1.0]])
    wall[:3, 3] = [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, pedestal_top + 0.02 + 2.0]
    checker.scene.add(CollisionObject("wall", "box", (0.01, 4.0, 2.0), wall))
    assert checker.is_valid(here) and checker.is_valid(there), checker.describe(here) + checker.describe(
        there
    )
    task = Task(
        "cross",
        [
            CurrentState(here),
            Connect(MotionSettings(planning_time=0.2, group="manipulator")),
            CurrentState(there, name="there"),
        ],
    )
    with pytest.raises(TaskPlanningError) as failure:
        plan_task(task, checker)
    message = str(failure.value)
    assert "stage 2 of 3 ('connect')" in message and "no collision-free path found within 0.20 s" in message
    assert [r.status for r in failure.value.reports] == ["solved", "failed", "solved"], failure.value.reports

    # The task's timeout cuts a longer search short: the connect searches only what is left of it.
    patient = Task(
        "cross",
        [
            CurrentState(here),
            Connect(MotionSettings(planning_time=30.0, group="manipulator")),
            CurrentState(there),
        ],
    )
    with pytest.raises(TaskPlanningError) as failure:
        plan_task(patient, checker, timeout=0.3)
    message = str(failure.value)
    assert "stage 2 of 3 ('connect')" in message, message
    assert re.search(r"within 0\.[0-3]\d s|planning timeout of 0\.30 s ran out", message), message


def test_collisions_allowed_by_a_scene_change_hold_for_the_stages_after_it_only(
    model: RobotModel, checker: CollisionChecker, start: np.ndarray, grasp: np.ndarray
) -> None:
    # A box the gripper closes around: at the grasp, the gripper's links touch it.
    checker.scene.add(CollisionObject("box", "box", (0.06, 0.06, 0.06), _at(*grasp[:3, 3])))
    with pytest.raises(TaskPlanningError) as failure:
        plan_task(pick_task(start, [grasp]), checker)
    assert "('grasp pose IK')" in str(failure.value), str(failure.value)

    stages = pick_task(start, [grasp]).stages
    allow = AllowCollisions(["gripper"], ["box"], name="touch the box")
    solution = plan_task(Task("pick", [*stages[:2], allow, *stages[2:]]), checker)
    assert [s.stage for s in solution.sub_trajectories] == ["connect", "approach"]
    (change,) = solution.scene_changes
    assert change.stage == "touch the box" and change.before == 1, change
    assert change.description == "collisions allowed: gripper - box"
    assert frozenset(("robotiq_85_left_finger_link", "box")) in change.allowed
    assert checker.allowed_collisions == frozenset(), "planning restores the checker's rules"
    # The connect, planned before the change, keeps clear of the box; the grasp touches it.
    checker.padding = 0.0
    connect = solution.sub_trajectories[0].trajectory
    rows = np.repeat(solution.start[None, :], len(connect.times), axis=0)
    rows[:, [model.index(n) for n in connect.joint_names]] = connect.positions
    assert checker.first_invalid(rows, 0.01) is None
    assert "box" in checker.describe(solution.end)
    # Replayed, the change comes along in its place.
    replay = plan_task(Task("replay", [FromSolution(solution)]), checker)
    assert [(c.description, c.before) for c in replay.scene_changes] == [(change.description, 1)]

    with pytest.raises(TaskPlanningError) as failure:
        plan_task(Task("typo", [CurrentState(start), AllowCollisions(["griper"], ["box"])]), checker)
    message = str(failure.value)
    assert "stage 2 of 2 ('allow collisions')" in message and "'griper'" in message, message
    assert "gripper" in message.split("'griper'")[1], message  # the likely name is suggested


def _at(x: float, y: float, z: float, like: np.ndarray | None = None) -> np.ndarray:
    pose = np.eye(4) if like is None else like.copy()
    pose[:3, 3] = [x, y, z]
    return pose


def test_a_task_can_go_on_from_an_earlier_solution(
    model: RobotModel, checker: CollisionChecker, start: np.ndarray, grasp: np.ndarray
) -> None:
    pick = plan_task(pick_task(start, [grasp]), checker)
    retreat = Task(
        "retreat",
        [
            FromSolution(pick),
            MoveAlongFrameAxis(
                (0, 0, 1),
                "world",
                "grasp_link",
                0.1,
                0.1,
                motion=MotionSettings(group="manipulator", link_padding=0.0),
            ),
        ],
    )
    solution = plan_task(retreat, checker)
    assert len(solution.sub_trajectories) == 3
    assert np.allclose(solution.start, pick.start)
    rise = fk(model, solution.end, "grasp_link")[:3, 3] - fk(model, pick.end, "grasp_link")[:3, 3]
    assert np.allclose(rise, [0, 0, 0.1], atol=1e-3), rise
    solution.joined()


def test_the_same_seed_plans_the_same_solution(
    checker: CollisionChecker, start: np.ndarray, grasp: np.ndarray
) -> None:
    a = plan_task(pick_task(start, [grasp]), checker).joined()
    b = plan_task(pick_task(start, [grasp]), checker).joined()
    assert a.positions.shape == b.positions.shape and np.allclose(a.positions, b.positions)


def test_badly_built_tasks_fail_naming_the_stage(
    checker: CollisionChecker, start: np.ndarray, grasp: np.ndarray
) -> None:
    cases = [
        (Task("empty"), "the task has no stages"),
        (
            Task(
                "no start",
                [
                    MoveAlongFrameAxis(
                        (0, 0, 1),
                        "world",
                        "tool0",
                        0.1,
                        0.1,
                        motion=MotionSettings(group="manipulator", link_padding=0.0),
                    )
                ],
            ),
            "starts with a state",
        ),
        (
            Task("dangling", [CurrentState(start), Connect(motion=MotionSettings(group="manipulator"))]),
            "needs a stage after it",
        ),
        (
            Task(
                "backwards",
                [
                    CurrentState(start),
                    Connect(motion=MotionSettings(group="manipulator")),
                    PlanToPose(("world", grasp), "grasp_link", motion=MotionSettings(group="manipulator")),
                    BatchPoseIK([("world", grasp)], "grasp_link", group="manipulator"),
                ],
            ),
            "stage 3 of 4 ('plan to pose')",
        ),
        (
            Task("group", [CurrentState(start), PlanToJointState({}, MotionSettings(group="arm"))]),
            "unknown planning group 'arm'",
        ),
    ]
    for task, expected in cases:
        with pytest.raises(TaskPlanningError) as failure:
            plan_task(task, checker)
        assert expected in str(failure.value), str(failure.value)


def test_link_padding_is_honoured_per_stage(
    checker: CollisionChecker, start: np.ndarray, arm_goal: Callable[[str], dict[str, float]]
) -> None:
    home = arm_goal("Home")
    plan_task(
        Task(
            "tight",
            [
                CurrentState(start),
                PlanToJointState(home, MotionSettings(link_padding=0.0, group="manipulator")),
            ],
        ),
        checker,
    )
    wide = Task(
        "wide",
        [CurrentState(start), PlanToJointState(home, MotionSettings(link_padding=0.5, group="manipulator"))],
    )
    with pytest.raises(TaskPlanningError) as failure:
        plan_task(wide, checker)
    assert "stage 2 of 2 ('plan to joint state')" in str(failure.value) and "collision" in str(failure.value)
    assert checker.padding == 0.01, "planning restores the checker's own padding"
