"""The seeded RRT-Connect: the same request and seed give the same path, in this process or another."""

from __future__ import annotations

import itertools
import json
import subprocess
import sys

import numpy as np
import pytest

from kinema.errors import MotionError
from kinema.motion import PlanningOptions, fk, plan_joint_goal
from kinema.motion.rrt import RrtOptions, rrt_connect
from kinema.motion.task import Task, plan_task
from kinema.motion.task_stages import Connect, CurrentState, MotionSettings

LOWER, UPPER = np.array([-1.0, -1.0]), np.array([1.0, 1.0])


def _outside_the_bar(q: np.ndarray) -> bool:
    """A square plane with a bar across its middle, open at both ends."""
    return not (abs(q[0]) < 0.2 and abs(q[1]) < 0.8)


def _segments_free(path: np.ndarray, valid, step: float = RrtOptions().max_step) -> bool:
    """Every state at the planner's resolution along the path is valid (what a discrete check promises)."""
    for a, b in itertools.pairwise(path):
        n = max(1, int(np.ceil(np.abs(b - a).max() / step)))
        if not all(valid(a + (b - a) * s / n) for s in range(n + 1)):
            return False
    return True


def test_the_same_seed_gives_the_same_path_and_another_seed_another() -> None:
    start, goal = np.array([-0.9, 0.0]), np.array([0.9, 0.0])
    paths = {
        seed: [rrt_connect(_outside_the_bar, start, goal, LOWER, UPPER, RrtOptions(seed=seed)) for _ in "ab"]
        for seed in (0, 1, 2)
    }
    for first, again in paths.values():
        np.testing.assert_array_equal(first, again)
        assert np.array_equal(first[0], start) and np.array_equal(first[-1], goal)
        assert _segments_free(first, _outside_the_bar)
        # Around the bar's end, not a wander: shorter than twice the way round.
        assert np.linalg.norm(np.diff(first, axis=0), axis=1).sum() < 2 * 2.6
    assert len({paths[s][0].tobytes() for s in paths}) == 3, "three seeds should find three paths"


def test_a_free_straight_line_is_the_path() -> None:
    path = rrt_connect(lambda q: True, np.array([-0.5, 0.5]), np.array([0.5, -0.5]), LOWER, UPPER)
    np.testing.assert_array_equal(path, [[-0.5, 0.5], [0.5, -0.5]])


def test_an_enclosed_goal_fails_after_max_iterations_or_at_the_timeout() -> None:
    def boxed_in(q: np.ndarray) -> bool:
        return not (0.4 < abs(q[0]) < 0.5 or 0.4 < abs(q[1]) < 0.5) or bool(np.abs(q).max() > 0.5)

    start, goal = np.array([0.0, 0.0]), np.array([0.8, 0.8])
    with pytest.raises(MotionError, match=r"in 200 iterations \(seeded RRT-Connect, seed 7\); raise max_it"):
        rrt_connect(boxed_in, start, goal, LOWER, UPPER, RrtOptions(seed=7, max_iterations=200))
    with pytest.raises(MotionError, match=r"within 0\.05 s \(seeded RRT-Connect"):
        rrt_connect(boxed_in, start, goal, LOWER, UPPER, RrtOptions(max_iterations=10**9, timeout=0.05))


def test_bad_options_are_refused() -> None:
    with pytest.raises(MotionError, match="max_iterations must be at least 1, got 0"):
        RrtOptions(max_iterations=0)
    with pytest.raises(MotionError, match="finite joint limits"):
        rrt_connect(lambda q: True, np.zeros(2), np.ones(2), np.array([-np.inf, 0.0]), np.ones(2) * 2)


def _blocked(model, checker, waypoint_q):
    """Mid point to pick pose with a block where the straight move takes the gripper halfway."""
    mid, pick = waypoint_q("3 Waypoint Mid Point"), waypoint_q("3 Waypoint Pick Pose")
    a, b = fk(model, mid, "grasp_link")[:3, 3], fk(model, pick, "grasp_link")[:3, 3]
    block = np.eye(4)
    block[:3, 3] = (a + b) / 2
    checker.scene.add_box("block", (0.03, 0.03, 0.03), block)
    assert checker.first_invalid(np.array([mid, pick]), 0.02) is not None
    return mid, pick


def test_a_seeded_plan_is_repeated_exactly_after_other_plans(model, checker, waypoint_q, arm_goal):
    mid, _ = _blocked(model, checker, waypoint_q)
    goal = arm_goal("3 Waypoint Pick Pose")
    options = PlanningOptions(timeout=5.0, seed=11)
    first = plan_joint_goal(checker, mid, goal, options=options, group="manipulator")
    # OMPL plans in between advance OMPL's process-wide generator; the seeded plan must not care.
    for _ in range(2):
        plan_joint_goal(checker, mid, goal, options=PlanningOptions(timeout=5.0), group="manipulator")
    again = plan_joint_goal(checker, mid, goal, options=options, group="manipulator")
    other = plan_joint_goal(
        checker, mid, goal, options=PlanningOptions(timeout=5.0, seed=12), group="manipulator"
    )
    np.testing.assert_array_equal(first.positions, again.positions)
    assert len(first.positions) > 2 and not np.array_equal(first.positions, other.positions)
    cols = list(model.group("manipulator").indices)
    for path in (first, other):
        rows = np.repeat(mid[None, :], len(path.positions), axis=0)
        rows[:, cols] = path.positions
        assert checker.first_invalid(rows, max_step=0.005) is None
    with pytest.raises(MotionError, match="planner 'PRM' cannot be seeded per plan"):
        plan_joint_goal(
            checker, mid, goal, options=PlanningOptions(planner="PRM", seed=1), group="manipulator"
        )


_IN_ANOTHER_PROCESS = """
import json, sys
import numpy as np
from kinema.motion import CollisionChecker, PlanningOptions, RobotDescription, fk, plan_joint_goal
d = RobotDescription.lab_sim(); model = d.load_model()
checker = CollisionChecker(model, d.load_scene(model), padding=0.01)
mid, goal = (np.array(v) for v in json.loads(sys.argv[1]))
block = np.eye(4); block[:3, 3] = json.loads(sys.argv[2])
checker.scene.add_box("block", (0.03, 0.03, 0.03), block)
cols = list(model.group("manipulator").indices)
names = model.group("manipulator").joint_names
options = PlanningOptions(timeout=5.0, seed=11)
targets = dict(zip(names, goal[cols], strict=True))
path = plan_joint_goal(checker, mid, targets, options=options, group="manipulator")
print(json.dumps(path.positions.tolist()))
"""


def test_a_seeded_plan_is_the_same_in_another_process(model, checker, waypoint_q, arm_goal):
    mid, pick = _blocked(model, checker, waypoint_q)
    here = plan_joint_goal(
        checker,
        mid,
        arm_goal("3 Waypoint Pick Pose"),
        options=PlanningOptions(timeout=5.0, seed=11),
        group="manipulator",
    )
    block = checker.scene.objects["block"].world_T_object[:3, 3].tolist()
    states = json.dumps([mid.tolist(), pick.tolist()])
    done = subprocess.run(
        [sys.executable, "-c", _IN_ANOTHER_PROCESS, states, json.dumps(block)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    there = np.array(json.loads(done.stdout.strip().splitlines()[-1]))
    np.testing.assert_allclose(there, here.positions, rtol=0, atol=1e-12)


def test_a_task_connect_around_an_obstacle_repeats_with_its_seed(model, checker, waypoint_q):
    mid, pick = _blocked(model, checker, waypoint_q)

    def plan(seed: int) -> np.ndarray:
        task = Task(
            "around",
            [CurrentState(mid), Connect(MotionSettings(seed=seed, group="manipulator")), CurrentState(pick)],
        )
        return plan_task(task, checker).joined().positions

    first = plan(5)
    plan_joint_goal(
        checker, mid, pick, options=PlanningOptions(timeout=5.0), group="manipulator"
    )  # OMPL, in between
    np.testing.assert_array_equal(plan(5), first)
    assert not np.array_equal(plan(6), first)
