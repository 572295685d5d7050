"""The cell works end to end through the driver: lab_sim's waypoints pick the cube, place it in the tray
and bring it back (joint-space moves, no planner), as "3 Waypoints Pick and Place" does."""

from __future__ import annotations

import numpy as np
from driver_harness import ARM, Sim, trajectory

from kinema.config import WaypointStore, resolve_config
from kinema.drivers.mujoco import names as n

CLOSED = 0.7929
PICK_SPOT = np.array([-0.30, 0.62])
TRAY_SPOT = np.array([0.30, 0.62])


def cube_xy(sim: Sim) -> np.ndarray:
    response = sim.service(n.BODIES_SERVICE, n.BODIES_TYPE).call(timeout=10.0)
    (cube,) = [b for b in response.bodies if b.name == "cube"]
    return np.array([cube.pose.position.x, cube.pose.position.y])


def test_the_cube_goes_into_the_tray_and_back(sim: Sim) -> None:
    path = resolve_config("lab_sim").waypoints_path
    assert path is not None
    store = WaypointStore(path)
    waypoints = {
        name: np.array([store.get(name).joint_positions()[joint] for joint in ARM])
        for name in ("3 Waypoint Mid Point", "3 Waypoint Pick Pose", "3 Waypoint Place Pose")
    }

    def move(name: str) -> None:
        result = sim.follow(trajectory(sim.joint_states.latest(), waypoints[name], 2.0)).result(60.0)
        assert result.succeeded, f"{name}: {result.result.error_string}"

    def transfer(source: str, target: str) -> None:
        move(source)
        grasp = sim.gripper(CLOSED)
        assert grasp.result.stalled, "the gripper closed on nothing"
        move("3 Waypoint Mid Point")
        move(target)
        assert sim.gripper(0.0).result.reached_goal
        move("3 Waypoint Mid Point")

    move("3 Waypoint Mid Point")
    assert sim.gripper(0.0).result.reached_goal
    transfer("3 Waypoint Pick Pose", "3 Waypoint Place Pose")
    np.testing.assert_allclose(cube_xy(sim), TRAY_SPOT, atol=0.02)
    transfer("3 Waypoint Place Pose", "3 Waypoint Pick Pose")
    np.testing.assert_allclose(cube_xy(sim), PICK_SPOT, atol=0.02)
