"""The trajectory controller's streaming input, ``/<controller>/joint_trajectory`` (ros2_control's topic).

Each trajectory replaces the one running (what the MPC behaviors stream every control step); an empty one
stops the arm, which brakes and holds; a bad one is refused and changes nothing.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from driver_harness import Sim, trajectory, wait_for

from kinema.drivers.mujoco import names as n

pytestmark = pytest.mark.slow  # real-time simulations

OFFSET = np.array([0.0, 0.4, -0.3, 0.3, 0.3, 0.3, 0.3])


def _publisher(sim: Sim) -> Any:
    """A publisher on the controller's topic, once the driver's subscription has matched it."""
    topic = n.joint_trajectory_topic(n.JOINT_TRAJECTORY_CONTROLLER)
    assert topic == "/joint_trajectory_controller/joint_trajectory"
    publisher = sim.node.create_publisher(n.JOINT_TRAJECTORY_TYPE, topic)
    wait_for(lambda: publisher.subscription_count() > 0, 10.0, f"the driver subscribing to {topic}")
    return publisher


def test_a_streamed_trajectory_moves_the_arm_and_the_next_replaces_it(start_sim: Callable[..., Sim]) -> None:
    sim = start_sim(sim_speed=1.0)
    publisher = _publisher(sim)
    start = sim.joint_states.latest()
    away = trajectory(start, start + OFFSET, 3.0)["trajectory"]
    publisher.publish(away)
    wait_for(lambda: np.abs(sim.joint_states.latest() - start).max() > 0.05, 10.0, "the arm to follow it")
    # Replaced on the way: the arm turns back to where it started instead of finishing the first.
    here = sim.joint_states.latest()
    publisher.publish(trajectory(here, start, 1.5)["trajectory"])
    sim.settle(2.5)
    np.testing.assert_allclose(sim.joint_states.latest(), start, atol=0.01)


def test_an_empty_trajectory_stops_the_arm_where_it_is(start_sim: Callable[..., Sim]) -> None:
    sim = start_sim(sim_speed=1.0)
    publisher = _publisher(sim)
    start = sim.joint_states.latest()
    publisher.publish(trajectory(start, start + OFFSET, 3.0)["trajectory"])
    wait_for(lambda: np.abs(sim.joint_states.latest() - start).max() > 0.1, 10.0, "the arm to move")
    publisher.publish({"joint_names": [], "points": []})
    sim.settle(0.3)
    stopped = sim.joint_states.latest()
    sim.settle(1.0)
    # Still, well short of the 3 s trajectory's end.
    np.testing.assert_allclose(sim.joint_states.latest(), stopped, atol=2e-3)
    assert np.abs(stopped - (start + OFFSET)).max() > 0.1


def test_a_trajectory_naming_unknown_joints_is_refused(start_sim: Callable[..., Sim]) -> None:
    sim = start_sim(sim_speed=1.0)
    publisher = _publisher(sim)
    start = sim.joint_states.latest()
    bad = trajectory(start, start + OFFSET, 1.0)["trajectory"]
    bad["joint_names"] = ["no_such_joint", *bad["joint_names"][1:]]
    publisher.publish(bad)
    sim.settle(0.5)
    np.testing.assert_allclose(sim.joint_states.latest(), start, atol=1e-3)
