"""Fixtures for the MuJoCo driver: a router on a free loopback port, the driver in-process, a client node.

The driver runs headless and, unless a test asks otherwise, as fast as it can (``sim_speed=inf``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from driver_harness import GRIPPER, JointStates, Sim

from kinema.config import WaypointStore, resolve_config
from kinema.drivers.mujoco import MujocoDriver, MujocoDriverSettings
from kinema.drivers.mujoco import names as n
from kinema.transport import Node, Session, free_endpoint, host_router, open_session


@pytest.fixture
def router_endpoint() -> Iterator[str]:
    endpoint = free_endpoint()
    router = host_router(endpoint)
    yield endpoint
    router.close()


@pytest.fixture
def start_sim(router_endpoint: str) -> Iterator[Callable[..., Sim]]:
    """Factory: ``start_sim(sim_speed=math.inf, **settings)`` starts a driver and a client for it."""
    started: list[tuple[MujocoDriver, Session, Session]] = []

    def start(sim_speed: float = math.inf, **overrides: Any) -> Sim:
        driver_session = open_session(router_endpoint)
        settings = MujocoDriverSettings.from_config("lab_sim", sim_speed=sim_speed, **overrides)
        driver = MujocoDriver(driver_session, settings)
        client_session = open_session(router_endpoint)
        started.append((driver, driver_session, client_session))
        driver.start()
        node = Node(client_session, "test_client")
        joint_states = JointStates()
        node.create_subscription(n.JOINT_STATES_TYPE, n.JOINT_STATES_TOPIC, joint_states.on_message)
        sim = Sim(driver, node, joint_states)
        joint_states.latest_stamp()
        return sim

    yield start
    for driver, driver_session, client_session in started:
        client_session.close()
        driver.stop()
        driver_session.close()


@pytest.fixture
def sim(start_sim: Callable[..., Sim]) -> Sim:
    """The lab_sim driver at max speed, from its ``default`` keyframe."""
    return start_sim()


@pytest.fixture
def pick_pose() -> dict[str, float]:
    """The arm joints of lab_sim's "3 Waypoint Pick Pose" (open gripper around the cube)."""
    path = resolve_config("lab_sim").waypoints_path
    assert path is not None
    joints = WaypointStore(path).get("3 Waypoint Pick Pose").joint_positions()
    return {name: value for name, value in joints.items() if name != GRIPPER}
