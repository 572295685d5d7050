"""The gripper controller: closing on the cube stalls, closing on nothing reaches the goal."""

from __future__ import annotations

import numpy as np
import pytest
from driver_harness import ARM, GRIPPER, Sim, trajectory

from kinema.drivers.mujoco import names as n
from kinema.transport import STATUS_ABORTED, STATUS_SUCCEEDED

CLOSED = 0.7929


def cube_position(sim: Sim) -> np.ndarray:
    response = sim.service(n.BODIES_SERVICE, n.BODIES_TYPE).call(timeout=10.0)
    (cube,) = [b for b in response.bodies if b.name == "cube"]
    return np.array([cube.pose.position.x, cube.pose.position.y, cube.pose.position.z])


def test_closing_on_the_cube_stalls_on_it(sim: Sim, pick_pose: dict[str, float]) -> None:
    assert sim.set_state(**pick_pose).success
    sim.settle(0.3)
    before = cube_position(sim)
    result = sim.gripper(CLOSED)
    assert result.status == STATUS_SUCCEEDED
    assert result.result.stalled
    assert not result.result.reached_goal
    # The 5 cm cube stops the fingers well short of closed, and stays where it was.
    assert 0.15 < result.result.position < 0.6
    assert result.result.effort > 0.5
    sim.settle(0.3)
    assert sim.joint_states.latest((GRIPPER,))[0] == pytest.approx(result.result.position, abs=0.02)
    np.testing.assert_allclose(cube_position(sim), before, atol=0.005)


def test_closing_on_nothing_reaches_the_goal(sim: Sim) -> None:
    result = sim.gripper(CLOSED)
    assert result.status == STATUS_SUCCEEDED
    assert result.result.reached_goal
    assert not result.result.stalled
    assert result.result.position == pytest.approx(CLOSED, abs=0.01)
    sim.settle(0.3)
    assert sim.joint_states.latest((GRIPPER,))[0] == pytest.approx(CLOSED, abs=0.01)


def test_opening_reaches_the_goal(sim: Sim) -> None:
    assert sim.gripper(CLOSED).result.reached_goal
    result = sim.gripper(0.05)
    assert result.result.reached_goal
    assert result.result.position == pytest.approx(0.05, abs=0.01)


def test_max_effort_caps_the_grip_force(sim: Sim, pick_pose: dict[str, float]) -> None:
    assert sim.set_state(**pick_pose).success
    sim.settle(0.3)
    gentle = sim.gripper(CLOSED, max_effort=0.5)
    assert gentle.result.stalled
    assert abs(gentle.result.effort) <= 0.5 + 1e-6
    firm = sim.gripper(CLOSED)
    assert firm.result.stalled
    assert firm.result.effort > 1.0


def test_an_arm_stopped_by_the_cube_says_it_touches_the_cube(sim: Sim, pick_pose: dict[str, float]) -> None:
    # Closed fingers driven down to the pick pose land on the cube's top: the trajectory aborts on a
    # tolerance, and the message names what is in the way.
    assert sim.gripper(CLOSED).status == STATUS_SUCCEEDED
    start = sim.joint_states.latest()
    goal = np.array([pick_pose[name] for name in ARM])
    result = sim.follow(trajectory(start, goal, 3.0)).result(60.0)
    assert result.status == STATUS_ABORTED, result.result.error_string
    assert "the robot touches cube (robotiq_85_left_finger_link" in result.result.error_string, (
        result.result.error_string
    )
