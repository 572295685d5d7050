"""Grasping in the lab_sim scene: the cube really travels with the closed gripper, and the waypoints work."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from kinema.motion import CollisionChecker, JointPath, plan_joint_goal, time_parameterize
from kinema.resources import bundled_dir

ARM = (
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
CLOSED = 0.7929
CUBE_WIDTH = 0.05
FINGER_PER_KNUCKLE = 0.0425 / 0.7929
TRAY_INNER = (0.12, 0.14)  # half extents of the tray floor


@pytest.fixture(scope="module")
def waypoints() -> dict[str, np.ndarray]:
    path = bundled_dir("configs") / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml"
    out = {}
    for e in yaml.safe_load(path.read_text()):
        by_name = dict(zip(e["joint_state"]["name"], e["joint_state"]["position"], strict=True))
        out[e["name"]] = np.array([by_name[j] for j in ARM])
    return out


@pytest.fixture(scope="module")
def planning(description):
    model = description.load_model()
    return model, CollisionChecker(model, description.load_scene(model), padding=0.01)


def _joint_move(cell, goal: np.ndarray, seconds: float = 1.5) -> None:
    """A smooth joint-space move straight to ``goal`` (no planner): the servos are driven directly."""
    start = cell.arm_q()
    t = np.linspace(0.0, seconds, 31)
    s = 3 * (t / seconds) ** 2 - 2 * (t / seconds) ** 3
    positions = start + np.outer(s, goal - start)
    velocities = np.gradient(positions, t, axis=0)
    from kinema.motion import JointTrajectory

    cell.track(JointTrajectory(ARM, t, positions, velocities, np.zeros_like(positions)))


def _planned_move(cell, planning, goal: np.ndarray) -> None:
    """Plan (OMPL or straight), time with toppra, then track: what "Move to Waypoint" does."""
    model, checker = planning
    start = model.configuration(dict(zip(ARM, cell.arm_q(), strict=True)))
    start[model.index("robotiq_85_left_knuckle_joint")] = np.clip(
        cell.qpos("robotiq_85_left_knuckle_joint"), 0.0, CLOSED
    )
    path: JointPath = plan_joint_goal(checker, start, dict(zip(ARM, goal, strict=True)), group="manipulator")
    cell.track(time_parameterize(path, model))


def _finger_gap(cell) -> float:
    opening = cell.qpos("robotiq_85_left_finger_joint") + cell.qpos("robotiq_85_right_finger_joint")
    return 0.085 - opening


def test_grasp_lift_carry_and_release(cell, waypoints):
    cube_start = cell.body_pos("cube")
    _joint_move(cell, waypoints["3 Waypoint Mid Point"])
    _joint_move(cell, waypoints["3 Waypoint Pick Pose"])
    assert np.linalg.norm(cell.body_pos("cube") - cube_start) < 2e-3, "the open gripper pushed the cube"

    cell.grip(CLOSED)
    # The fingers stop on the cube (not on the table, not closed on air): the gap is the cube's width.
    assert _finger_gap(cell) == pytest.approx(CUBE_WIDTH, abs=2e-3)
    knuckle = cell.qpos("robotiq_85_left_knuckle_joint")
    assert knuckle == pytest.approx((0.085 - CUBE_WIDTH) / 2 / FINGER_PER_KNUCKLE, abs=0.02)

    grasp_offset = cell.body_pos("cube") - cell.d.site("grasp_site").xpos
    _joint_move(cell, waypoints["3 Waypoint Mid Point"])
    lifted = cell.body_pos("cube")
    assert lifted[2] > cube_start[2] + 0.2
    # The cube came along rigidly: its offset from the grasp point barely changed.
    assert np.linalg.norm(lifted - cell.d.site("grasp_site").xpos - grasp_offset) < 3e-3

    _joint_move(cell, waypoints["3 Waypoint Place Pose"])
    cell.grip(0.0)
    cell.step(0.5)
    assert _finger_gap(cell) == pytest.approx(0.085, abs=1e-3)
    _joint_move(cell, waypoints["3 Waypoint Mid Point"])
    placed = cell.body_pos("cube")
    tray = cell.body_pos("tray")
    assert np.all(np.abs(placed[:2] - tray[:2]) < np.array(TRAY_INNER) - CUBE_WIDTH / 2)
    assert placed[2] == pytest.approx(tray[2] + 0.004 + CUBE_WIDTH / 2, abs=2e-3)  # resting on the tray floor


def test_three_waypoint_pick_and_place_cycle_with_the_planner(cell, waypoints, planning):
    """The sequence of "3 Waypoints Pick and Place", twice: pick -> tray -> back, positions within 2 cm."""
    cube_start = cell.body_pos("cube")
    block_start = cell.body_pos("tag_block")
    tray = cell.body_pos("tray")
    _planned_move(cell, planning, waypoints["3 Waypoint Mid Point"])
    cell.grip(0.0)
    for _ in range(2):
        for waypoint, grip in [
            ("3 Waypoint Pick Pose", CLOSED),
            ("3 Waypoint Mid Point", None),
            ("3 Waypoint Place Pose", 0.0),
            ("3 Waypoint Mid Point", None),
        ]:
            _planned_move(cell, planning, waypoints[waypoint])
            if grip is not None:
                cell.grip(grip)
        in_tray = cell.body_pos("cube")
        assert np.linalg.norm(in_tray[:2] - tray[:2]) < 0.02
        for waypoint, grip in [
            ("3 Waypoint Place Pose", CLOSED),
            ("3 Waypoint Mid Point", None),
            ("3 Waypoint Pick Pose", 0.0),
            ("3 Waypoint Mid Point", None),
        ]:
            _planned_move(cell, planning, waypoints[waypoint])
            if grip is not None:
                cell.grip(grip)
        back = cell.body_pos("cube")
        assert np.linalg.norm(back - cube_start) < 0.02
        # Upright: the cube's z axis still points up (it was not tipped over on the way).
        assert cell.d.body("cube").xmat.reshape(3, 3)[2, 2] > 0.99
        # The AprilTag block standing between the pick spot and the tray is never touched.
        assert np.linalg.norm(cell.body_pos("tag_block") - block_start) < 2e-3
