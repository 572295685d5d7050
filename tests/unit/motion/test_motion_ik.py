from __future__ import annotations

import numpy as np
import pytest

from kinema.errors import MotionError
from kinema.motion import IkOptions, fk, ik


def _pose_error(A: np.ndarray, B: np.ndarray) -> tuple[float, float]:
    rot = np.arccos(np.clip((np.trace(A[:3, :3].T @ B[:3, :3]) - 1) / 2, -1, 1))
    return float(np.linalg.norm(A[:3, 3] - B[:3, 3])), float(rot)


def test_ik_round_trip_from_random_reachable_poses(model, waypoint_q):
    rng = np.random.default_rng(7)
    seed = waypoint_q("3 Waypoint Mid Point")
    arm = list(model.group("manipulator").indices)
    for _ in range(20):
        q_true = seed.copy()
        # Poses near the work area: perturb the mid point so the targets stay reachable.
        q_true[arm] += rng.uniform(-0.6, 0.6, len(arm))
        q_true = np.clip(q_true, model.lower, model.upper)
        target = fk(model, q_true, "grasp_link")
        q = ik(model, target, seed, group="manipulator")
        pos, rot = _pose_error(fk(model, q, "grasp_link"), target)
        assert pos < 1e-4 and rot < 1e-3
        assert model.within_limits(q)


def test_ik_keeps_joints_outside_the_group(model, waypoint_q):
    seed = waypoint_q("3 Waypoint Mid Point")
    seed[model.index("robotiq_85_left_knuckle_joint")] = 0.4
    target = fk(model, waypoint_q("3 Waypoint Pick Pose"), "grasp_link")
    q = ik(model, target, seed, group="manipulator")
    assert q[model.index("robotiq_85_left_knuckle_joint")] == 0.4


def test_ik_prefers_the_seed_branch(model, waypoint_q):
    """Solving for the pick pose from the mid point lands on the waypoint itself, not another branch."""
    pick = waypoint_q("3 Waypoint Pick Pose")
    q = ik(model, fk(model, pick, "grasp_link"), waypoint_q("3 Waypoint Mid Point"), group="manipulator")
    arm = list(model.group("manipulator").indices)[1:]  # the rail is redundant: it may settle elsewhere
    assert np.abs(q[arm] - pick[arm]).max() < 0.3


def test_ik_honours_tight_limits(model, waypoint_q):
    """A target only reachable with the rail far out fails when the rail group is excluded."""
    seed = waypoint_q("3 Waypoint Mid Point")
    far = np.eye(4)
    far[:3, :3] = fk(model, seed, "grasp_link")[:3, :3]
    far[:3, 3] = (0.5, 2.4, 0.95)  # 2.4 m along the rail: beyond the 1.2 m rail plus the arm's sideways reach
    with pytest.raises(MotionError, match="no IK solution for 'grasp_link' in group 'manipulator'"):
        ik(model, far, seed, options=IkOptions(attempts=4), group="manipulator")


def test_ik_position_only(model, waypoint_q):
    seed = waypoint_q("3 Waypoint Mid Point")
    target = np.eye(4)
    target[:3, 3] = (0.55, 0.1, 1.0)
    q = ik(model, target, seed, position_only=True, group="manipulator")
    assert np.linalg.norm(fk(model, q, "grasp_link")[:3, 3] - target[:3, 3]) < 1e-4


def test_ik_accept_hook_rejects_solutions(model, waypoint_q):
    target = fk(model, waypoint_q("3 Waypoint Pick Pose"), "grasp_link")
    with pytest.raises(MotionError, match="rejected"):
        ik(
            model,
            target,
            waypoint_q("3 Waypoint Mid Point"),
            options=IkOptions(attempts=2),
            accept=lambda q: False,
            group="manipulator",
        )


def test_ik_group_without_tip_needs_a_frame(model):
    with pytest.raises(MotionError, match="has no tip link"):
        ik(model, np.eye(4), model.neutral(), group="gripper")


def test_restarts_return_the_solution_closest_to_the_seed(model, waypoint_q):
    """When the seed itself cannot converge (one iteration allowed), restarts run and the closest wins."""
    pick = waypoint_q("3 Waypoint Pick Pose")
    target = fk(model, pick, "grasp_link")
    seed = waypoint_q("3 Waypoint Mid Point")
    few = IkOptions(max_iterations=1, attempts=3)
    with pytest.raises(MotionError, match="no IK solution"):
        ik(model, target, seed, options=few, group="manipulator")
    solutions = []
    opts = IkOptions(attempts=40, restart_solutions=3, rng_seed=3)

    def record(q):
        solutions.append(q.copy())
        return len(solutions) > 1  # reject the seed's own solution so that restarts have to run

    q = ik(model, target, seed, options=opts, accept=record, group="manipulator")
    accepted = solutions[1:]
    assert len(accepted) == 3
    assert np.linalg.norm(q - seed) == pytest.approx(min(np.linalg.norm(s - seed) for s in accepted))
