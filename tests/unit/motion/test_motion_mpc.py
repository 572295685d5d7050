"""kinema.motion.mpc: the QP per control step tracks a moving target within the joint limits and keeps
its clearance, on lab_sim's model with the plan executed exactly (each step starts where the last plan's
first point was)."""

from __future__ import annotations

import numpy as np
import pytest

from kinema.errors import MotionError
from kinema.motion import RobotModel, fk
from kinema.motion.mpc import MpcSettings, Obstacles, PoseTrackingMpc, target_path

DT = 0.01
START = {"shoulder_lift_joint": -1.2, "elbow_joint": 1.5, "wrist_1_joint": -1.9, "wrist_2_joint": -1.57}
TWIST = np.array([-0.09, -0.04, 0.0, 0.0, 0.0, -0.1])  # MoveIt Pro's "MPC Pose Tracking" target, about


def _run(
    model: RobotModel,
    mpc: PoseTrackingMpc,
    target_at: object,
    steps: int,
    obstacles: Obstacles | None = None,
    twist: np.ndarray | None = None,
) -> tuple[np.ndarray, list[np.ndarray], list[object]]:
    """Steps the MPC, each from the previous plan's first point: (final q, every q, every plan)."""
    q = model.configuration(START)
    columns = np.array(mpc.group.indices)
    configurations, plans = [], []
    for k in range(steps):
        plan = mpc.step(q, k * DT, target_at(k * DT), twist, obstacles)  # type: ignore[operator]
        q = q.copy()
        q[columns] = plan.positions[0]
        configurations.append(q)
        plans.append(plan)
    return q, configurations, plans


@pytest.mark.slow  # hundreds of QP steps
def test_it_tracks_a_target_moving_along_a_line_while_turning(model: RobotModel) -> None:
    start = fk(model, model.configuration(START), "pinch")
    offset = start.copy()
    offset[:3, 3] += [-0.08, -0.04, 0.0]  # where MoveIt Pro's objective starts its target

    def target_at(t: float) -> np.ndarray:
        return target_path(offset, TWIST, np.array([t]))[0]

    mpc = PoseTrackingMpc(model, "manipulator", "pinch", MpcSettings(horizon=0.2, timestep=DT))
    _, configurations, plans = _run(model, mpc, target_at, 300, twist=TWIST)
    errors = [
        float(np.linalg.norm(fk(model, q, "pinch")[:3, 3] - target_at((k + 1) * DT)[:3, 3]))
        for k, q in enumerate(configurations)
    ]
    assert errors[0] > 0.005  # it starts 9 cm away and closes in at the joints' limits
    assert max(errors[100:]) < 0.002, max(errors[100:])  # then stays on the moving target
    final = fk(model, configurations[-1], "pinch")
    turned = final[:3, :3].T @ target_at(300 * DT)[:3, :3]
    assert np.arccos(np.clip((np.trace(turned) - 1) / 2, -1, 1)) < 0.01  # orientation too
    assert plans[-1].position_error < 0.002 and plans[-1].cost < 1e-4


@pytest.mark.slow  # hundreds of QP steps
def test_the_plan_respects_the_joint_velocity_limits_and_a_cartesian_speed_limit(model: RobotModel) -> None:
    start = fk(model, model.configuration(START), "pinch")
    far = start.copy()
    far[:3, 3] += [0.3, -0.2, -0.1]
    settings = MpcSettings(horizon=0.2, timestep=DT, cartesian_frame="tool0", max_cartesian_speed=0.2)
    mpc = PoseTrackingMpc(model, "manipulator", "pinch", settings)
    _, configurations, plans = _run(model, mpc, lambda _t: far, 400)
    columns = np.array(mpc.group.indices)
    limits = model.max_velocity[columns]
    for plan in plans:
        assert (np.abs(plan.velocities) <= limits * (1 + 1e-4) + 1e-6).all()
        assert (plan.positions >= model.lower[columns] - 1e-6).all()
        assert (plan.positions <= model.upper[columns] + 1e-6).all()
    tool = np.array([fk(model, q, "tool0")[:3, 3] for q in configurations])
    speeds = np.linalg.norm(np.diff(tool, axis=0), axis=1) / DT
    assert speeds.max() < 0.2 * 1.05, speeds.max()  # linearised: a few percent at most over
    assert speeds.max() > 0.1  # and it does move at about the limit
    assert float(np.linalg.norm(fk(model, configurations[-1], "pinch")[:3, 3] - far[:3, 3])) < 0.01


@pytest.mark.slow  # hundreds of QP steps
def test_joint_position_limits_hold_when_the_target_is_out_of_reach(model: RobotModel) -> None:
    start = fk(model, model.configuration(START), "pinch")
    unreachable = start.copy()
    unreachable[:3, 3] += [3.0, 0.0, 0.0]  # far along the rail, beyond its end
    mpc = PoseTrackingMpc(model, "manipulator", "pinch", MpcSettings(horizon=0.1, timestep=DT))
    _, configurations, _ = _run(model, mpc, lambda _t: unreachable, 400)
    columns = np.array(mpc.group.indices)
    everything = np.array(configurations)[:, columns]
    assert (everything >= model.lower[columns] - 1e-6).all()
    assert (everything <= model.upper[columns] + 1e-6).all()
    rail = model.index("linear_rail_joint")
    rail_ends = (model.lower[rail], model.upper[rail])
    assert min(abs(configurations[-1][rail] - end) for end in rail_ends) < 1e-3  # pressed to the end


@pytest.mark.slow  # hundreds of QP steps
def test_it_keeps_the_safe_distance_from_a_sphere_in_the_way(model: RobotModel) -> None:
    start = fk(model, model.configuration(START), "pinch")
    below = start.copy()
    below[:3, 3] += [0.0, 0.0, -0.25]
    sphere = Obstacles.from_spheres([start[:3, 3] + [0.0, 0.0, -0.12]], 0.03)
    settings = MpcSettings(horizon=0.1, timestep=DT, clearance_frames=("pinch",), safe_distance=0.05)
    mpc = PoseTrackingMpc(model, "manipulator", "pinch", settings)
    _, configurations, plans = _run(model, mpc, lambda _t: below, 250, sphere)
    clearances = [sphere.distance(fk(model, q, "pinch")[:3, 3]) for q in configurations]
    assert min(clearances) > 0.05 - 2e-3, min(clearances)
    # Without the sphere the straight way passes through it: the clearance is what kept it off.
    free = PoseTrackingMpc(model, "manipulator", "pinch", MpcSettings(horizon=0.1, timestep=DT))
    _, free_path, _ = _run(model, free, lambda _t: below, 250)
    assert min(sphere.distance(fk(model, q, "pinch")[:3, 3]) for q in free_path) < 0.03
    # It went round: the target (5 cm past the sphere's far side) is reached.
    assert plans[-1].position_error < 0.03, plans[-1].position_error


@pytest.mark.slow  # hundreds of QP steps
def test_a_frame_starting_inside_the_clearance_backs_out(model: RobotModel) -> None:
    start = fk(model, model.configuration(START), "pinch")
    cloud = Obstacles.from_points(start[:3, 3] + np.array([[0.0, 0.05, 0.0], [0.0, 0.06, 0.01]]))
    settings = MpcSettings(horizon=0.1, timestep=DT, clearance_frames=("pinch",), safe_distance=0.15)
    mpc = PoseTrackingMpc(model, "manipulator", "pinch", settings)
    _, configurations, _ = _run(model, mpc, lambda _t: start, 300, cloud)
    clearances = [cloud.distance(fk(model, q, "pinch")[:3, 3]) for q in configurations]
    assert clearances[0] >= 0.05 - 1e-3  # never closer than where it started
    assert min(clearances) >= 0.05 - 1e-3
    assert clearances[-1] > 0.14, clearances[-1]


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        (MpcSettings(horizon=0.001, timestep=0.01), "at least one timestep"),
        (MpcSettings(timestep=0.0), "timestep must be > 0"),
        (MpcSettings(max_cartesian_speed=-1.0, cartesian_frame="tool0"), "Cartesian speed"),
    ],
)
def test_settings_out_of_range_are_refused(model: RobotModel, settings: MpcSettings, message: str) -> None:
    with pytest.raises(MotionError, match=message):
        PoseTrackingMpc(model, "manipulator", "pinch", settings)


def test_unknown_frames_and_groups_name_the_valid_ones(model: RobotModel) -> None:
    with pytest.raises(MotionError, match=r"unknown frame 'pinchh'.*pinch"):
        PoseTrackingMpc(model, "manipulator", "pinchh", MpcSettings())
    with pytest.raises(MotionError, match="unknown planning group"):
        PoseTrackingMpc(model, "arm", "pinch", MpcSettings())


def test_obstacle_queries_rank_by_surface_distance() -> None:
    obstacles = Obstacles.from_spheres([[1.0, 0.0, 0.0], [0.0, 1.2, 0.0], [0.0, 0.0, 3.0]], [0.1, 0.9, 0.0])
    index, distance = obstacles.nearest(np.zeros(3), 2)
    assert index.tolist() == [1, 0]
    assert distance == pytest.approx([0.3, 0.9])
    assert Obstacles.from_points(np.zeros((0, 3))).distance(np.zeros(3)) == float("inf")
