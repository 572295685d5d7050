from __future__ import annotations

import numpy as np
import pytest

from kinema.errors import MotionError
from kinema.motion import CollisionChecker, PlanningScene, fk

HOME = {"shoulder_lift_joint": -2.0, "elbow_joint": 2.0, "wrist_1_joint": -1.5708, "wrist_2_joint": -1.5708}


def test_scene_has_the_static_world_of_the_mjcf(lab_scene):
    assert {"table", "floor", "tray_floor", "tray_wall_left"} <= set(lab_scene.objects)
    assert "cube" not in lab_scene.objects  # a free body: the object to pick, not an obstacle
    assert not any(name.startswith(("base", "shoulder", "rail")) for name in lab_scene.objects)
    table = lab_scene.objects["table"]
    assert table.world_T_object[2, 3] + table.size[2] == pytest.approx(0.474)  # MoveIt Pro's desk height


def test_all_waypoints_are_collision_free(checker, waypoints, waypoint_q):
    for name in waypoints:
        assert not checker.in_collision(waypoint_q(name)), f"{name}: {checker.describe(waypoint_q(name))}"


def test_self_collision_is_detected(model, checker):
    # Upper arm straight up, elbow folded back: the gripper swings into the upper arm.
    q = model.configuration({**HOME, "shoulder_lift_joint": -1.57, "elbow_joint": 2.6, "wrist_1_joint": 0.0})
    pairs = checker.colliding_pairs(q)
    assert ("upper_arm_link", "robotiq_85_base_link") in pairs
    assert all(b != "table" for _, b in pairs)


def test_table_collision_is_detected(model, checker):
    q = model.configuration({**HOME, "shoulder_lift_joint": -0.2, "elbow_joint": 0.5, "wrist_1_joint": -1.8})
    assert checker.in_collision(q)
    assert "table" in checker.describe(q)


def test_padding_keeps_distance_from_the_scene(checker, waypoint_q):
    pick = waypoint_q("3 Waypoint Pick Pose")  # fingertips 25 mm above the table
    checker.padding = 0.01
    assert not checker.in_collision(pick)
    checker.padding = 0.03
    assert checker.in_collision(pick)
    assert "table" in checker.describe(pick)
    with pytest.raises(MotionError, match="padding must be >= 0"):
        checker.padding = -0.1


def test_srdf_disabled_pairs_are_not_checked(model, checker):
    """The fingers touch each other when the empty gripper closes; the SRDF disables that pair."""
    q = model.configuration({**HOME, "robotiq_85_left_knuckle_joint": 0.7929})
    assert not checker.in_collision(q)


def test_added_objects_take_effect_and_can_be_removed(model, checker, waypoint_q):
    mid = waypoint_q("3 Waypoint Mid Point")
    T = np.eye(4)
    T[:3, 3] = fk(model, mid, "grasp_link")[:3, 3]
    checker.scene.add_box("obstacle", (0.05, 0.05, 0.05), T)
    assert "obstacle" in checker.describe(mid)
    checker.scene.remove("obstacle")
    assert not checker.in_collision(mid)
    with pytest.raises(MotionError, match="no collision object 'obstacle'"):
        checker.scene.remove("obstacle")


def test_unknown_shapes_are_rejected():
    from kinema.motion import CollisionObject

    with pytest.raises(MotionError, match="unknown collision shape 'cone'"):
        PlanningScene().add(CollisionObject("c", "cone", (1.0,), np.eye(4)))


def test_first_invalid_finds_the_colliding_segment(model, lab_scene, waypoint_q):
    checker = CollisionChecker(model, lab_scene, padding=0.0)
    mid = waypoint_q("3 Waypoint Mid Point")
    through_table = model.configuration({**HOME, "shoulder_lift_joint": -0.2, "elbow_joint": 0.5}, mid)
    assert checker.first_invalid(np.array([mid, waypoint_q("Home")])) is None
    assert checker.first_invalid(np.array([waypoint_q("Home"), mid, through_table])) == 1


def test_free_bodies_can_join_the_scene(description, model):
    scene = PlanningScene.from_mjcf(description.mjcf, model.link_names, include_free_bodies=True)
    cube = scene.objects["cube"]
    assert cube.shape == "box" and cube.size == pytest.approx((0.025, 0.025, 0.025))
    np.testing.assert_allclose(cube.world_T_object[:3, 3], (-0.30, 0.62, 0.499), atol=1e-6)


def test_importing_motion_is_light():
    import subprocess
    import sys

    code = (
        "import sys, kinema.motion, kinema.motion.trajectory;"
        "print([m for m in ('pinocchio', 'ompl', 'toppra', 'mujoco', 'coal') if m in sys.modules])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_checkers_of_one_model_read_its_collision_shapes_once(lab_scene, waypoint_q, monkeypatch):
    """Every planning thread gets its own checker; the shapes (meshes, their bounding-volume trees) are
    read once per model: an SO-ARM's 34 STL meshes cost 1.5-2.7 s per checker, paid at each first plan.
    Checkers sharing them still answer alike, each with its own padding."""
    import pinocchio as pin

    from kinema.motion import RobotDescription

    fresh = RobotDescription.lab_sim().load_model()
    reads = []
    build = pin.buildGeomFromUrdf
    monkeypatch.setattr(pin, "buildGeomFromUrdf", lambda *a, **k: reads.append(a[1]) or build(*a, **k))
    first, second = CollisionChecker(fresh, lab_scene), CollisionChecker(fresh, lab_scene, padding=0.05)
    assert len(reads) == 1
    pick = waypoint_q("3 Waypoint Pick Pose")  # fingertips 25 mm above the table
    assert first.in_collision(pick) is False and second.in_collision(pick) is True  # padding per checker
    assert CollisionChecker(fresh, lab_scene).colliding_pairs(pick) == first.colliding_pairs(pick) == []
