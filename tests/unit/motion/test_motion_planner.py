from __future__ import annotations

import numpy as np
import pytest

from kinema.errors import MotionError
from kinema.motion import PlanningOptions, fk, plan_joint_goal

PICK_AND_PLACE = [
    ("3 Waypoint Mid Point", "3 Waypoint Pick Pose"),
    ("3 Waypoint Pick Pose", "3 Waypoint Mid Point"),
    ("3 Waypoint Mid Point", "3 Waypoint Place Pose"),
    ("3 Waypoint Place Pose", "3 Waypoint Mid Point"),
    ("Home", "Look at Table"),
    ("Look at Table", "3 Waypoint Mid Point"),
    ("3 Waypoint Mid Point", "Home"),
]


def _full(model, start, path):
    cols = list(model.group("manipulator").indices)
    rows = np.repeat(start[None, :], len(path.positions), axis=0)
    rows[:, cols] = path.positions
    return rows


@pytest.mark.parametrize(("start", "goal"), PICK_AND_PLACE)
def test_waypoint_moves_are_planned_and_collision_free(model, checker, waypoint_q, arm_goal, start, goal):
    q0 = waypoint_q(start)
    path = plan_joint_goal(checker, q0, arm_goal(goal), group="manipulator")
    assert path.joint_names == model.group("manipulator").joint_names
    np.testing.assert_allclose(path.positions[0], q0[:7])
    np.testing.assert_allclose(path.positions[-1], waypoint_q(goal)[:7], atol=1e-9)
    assert checker.first_invalid(_full(model, q0, path), max_step=0.005) is None


def test_reset_mujoco_robot_pose_plans_to_every_waypoint(model, checker, waypoints, arm_goal):
    """The pose the compat objective "Reset MuJoCo Robot" sets (arm straight up) is a valid start."""
    reset = model.configuration({"shoulder_lift_joint": -1.57})
    assert not checker.in_collision(reset)
    for name in waypoints:
        path = plan_joint_goal(checker, reset, arm_goal(name), group="manipulator")
        assert checker.first_invalid(_full(model, reset, path), max_step=0.005) is None


def test_planner_goes_around_an_obstacle(model, checker, waypoint_q, arm_goal):
    """A wall between mid point and pick pose: the straight move is blocked and OMPL finds a way."""
    mid, pick = waypoint_q("3 Waypoint Mid Point"), waypoint_q("3 Waypoint Pick Pose")
    a, b = fk(model, mid, "grasp_link")[:3, 3], fk(model, pick, "grasp_link")[:3, 3]
    block = np.eye(4)
    block[:3, 3] = (a + b) / 2  # where the straight move takes the gripper halfway
    checker.scene.add_box("block", (0.03, 0.03, 0.03), block)
    assert checker.first_invalid(np.array([mid, pick]), 0.02) is not None
    path = plan_joint_goal(
        checker,
        mid,
        arm_goal("3 Waypoint Pick Pose"),
        options=PlanningOptions(timeout=5.0),
        group="manipulator",
    )
    assert len(path.positions) > 2
    assert checker.first_invalid(_full(model, mid, path), max_step=0.005) is None


def test_goal_in_collision_names_the_links(model, checker, waypoint_q):
    goal = {"shoulder_lift_joint": -0.2, "elbow_joint": 0.5, "wrist_1_joint": -1.8}
    with pytest.raises(MotionError, match=r"goal state is in collision: .*table"):
        plan_joint_goal(checker, waypoint_q("Home"), goal, group="manipulator")


def test_start_in_collision(model, checker, waypoint_q, arm_goal):
    start = model.configuration({"shoulder_lift_joint": -0.2, "elbow_joint": 0.5}, waypoint_q("Home"))
    with pytest.raises(MotionError, match=r"start state is in collision"):
        plan_joint_goal(checker, start, arm_goal("Home"), group="manipulator")


def test_a_start_touching_the_scene_is_left_for_a_nearby_free_state(model, checker, waypoint_q, arm_goal):
    """A gripper resting on a surface (inside the link padding) plans away from it, as MoveIt's
    FixStartStateCollision adapter lets it: the path starts where the arm is, then a short move frees it."""
    start = waypoint_q("VFC Start")  # the gripper pointing straight down above the table
    grasp = fk(model, start, "grasp_link")
    slab = np.eye(4)
    slab[:3, 3] = grasp[:3, 3] - np.array(
        [0.0, 0.0, 0.045]
    )  # its top 15 mm below grasp_link: 5 mm into the fingertips
    checker.scene.add_box("slab", (0.06, 0.06, 0.03), slab)  # half extents
    try:
        assert checker.in_collision(start), "the fingertips should reach into the slab"
        with pytest.raises(MotionError, match=r"start state is in collision: .*slab"):
            plan_joint_goal(
                checker,
                start,
                arm_goal("Home"),
                options=PlanningOptions(fix_start_collision=False),
                group="manipulator",
            )
        path = plan_joint_goal(checker, start, arm_goal("Home"), group="manipulator")
        cols = list(model.group("manipulator").indices)
        np.testing.assert_allclose(path.positions[0], start[cols])
        freed = _full(model, start, path)[1]
        assert not checker.in_collision(freed)
        span = (model.upper - model.lower)[cols]
        assert np.all(np.abs(freed[cols] - start[cols]) <= 0.01 * span + 1e-9)
        assert checker.first_invalid(_full(model, start, path)[1:], max_step=0.005) is None
        np.testing.assert_allclose(path.positions[-1], waypoint_q("Home")[cols], atol=1e-9)
    finally:
        checker.scene.remove("slab")


def test_unknown_joint_names_list_the_valid_ones(checker, waypoint_q):
    with pytest.raises(MotionError, match=r"unknown joint 'elbow'; did you mean 'elbow_joint'") as info:
        plan_joint_goal(checker, waypoint_q("Home"), {"elbow": 1.0}, group="manipulator")
    assert str(info.value).lower().count("valid") == 1  # the valid joints listed once
    assert "linear_rail_joint, robotiq_85_left_knuckle_joint, shoulder_lift_joint" in str(info.value)


def test_joint_outside_the_group_is_rejected(checker, waypoint_q):
    with pytest.raises(
        MotionError, match=r"'robotiq_85_left_knuckle_joint' is not in planning group 'manipulator'"
    ):
        plan_joint_goal(
            checker, waypoint_q("Home"), {"robotiq_85_left_knuckle_joint": 0.5}, group="manipulator"
        )


def test_goal_outside_limits(checker, waypoint_q):
    with pytest.raises(MotionError, match=r"linear_rail_joint = 1.5000 is outside its limits"):
        plan_joint_goal(checker, waypoint_q("Home"), {"linear_rail_joint": 1.5}, group="manipulator")


def test_unknown_group_and_planner(checker, waypoint_q):
    with pytest.raises(MotionError, match=r"unknown planning group 'arm'"):
        plan_joint_goal(checker, waypoint_q("Home"), {}, group="arm")
    with pytest.raises(MotionError, match=r"unknown planner 'RRTConect'.*RRTConnect"):
        plan_joint_goal(
            checker, waypoint_q("Home"), {}, options=PlanningOptions(planner="RRTConect"), group="manipulator"
        )


def test_unreachable_goal_times_out_with_a_reason(model, checker, waypoint_q):
    """A wall across the rail: moving only the rail, the arm can never get past it. The planner must give
    up at its timeout (and say so) instead of hanging."""
    home = waypoint_q("Home")
    wall = np.eye(4)
    wall[:3, 3] = (-0.5, 0.3, 0.824)  # the rail runs along world -x as its joint grows
    checker.scene.add_box("wall", (0.01, 0.15, 0.25), wall)
    goal = {"linear_rail_joint": 0.9}
    assert not checker.in_collision(home)
    assert not checker.in_collision(model.configuration(goal, home))
    with pytest.raises(MotionError, match=r"no collision-free path found within 0.30 s \(RRTConnect"):
        plan_joint_goal(checker, home, goal, group="linear_actuator", options=PlanningOptions(timeout=0.3))


@pytest.mark.parametrize(
    ("start", "goal", "object_at"),
    [
        ("3 Waypoint Mid Point", "3 Waypoint Pick Pose", "table"),
        ("3 Waypoint Mid Point", "3 Waypoint Place Pose", "tray"),
    ],
)
def test_open_gripper_comes_down_around_the_cube_without_touching_it(
    model, description, waypoint_q, arm_goal, start, goal, object_at
):
    """The planned approach never touches the cube waiting at the pick (or place) spot, though the planner
    does not know the cube is there: the waypoints make the straight move come down around it."""
    from kinema.motion import CollisionChecker, PlanningScene

    scene = PlanningScene.from_mjcf(description.mjcf, model.link_names, include_free_bodies=True)
    cube = scene.objects.pop("cube")
    planner_checker = CollisionChecker(model, scene, padding=0.01)
    path = plan_joint_goal(planner_checker, waypoint_q(start), arm_goal(goal), group="manipulator")
    if object_at == "tray":
        T = cube.world_T_object.copy()
        T[1, 3] = -T[1, 3]  # the tray spot mirrors the pick spot across the rail's middle
        T[2, 3] += 0.004  # on the tray floor
        cube = type(cube)(cube.name, cube.shape, cube.size, T)
    with_cube = PlanningScene({"cube": cube})
    cube_checker = CollisionChecker(model, with_cube, padding=0.005)
    assert cube_checker.first_invalid(_full(model, waypoint_q(start), path), max_step=0.002) is None
