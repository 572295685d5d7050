"""Fixtures: lab_sim's MuJoCo driver at max speed and a behavior context talking to it (no agent)."""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import pytest

from kinema.behaviors import BehaviorContext
from kinema.plugins import BehaviorHost, BehaviorRegistry


@pytest.fixture(scope="module")
def endpoint() -> Iterator[str]:
    """A router on a free loopback port."""
    from kinema.transport import free_endpoint, host_router

    address = free_endpoint()
    router = host_router(address)
    yield address
    router.close()


@pytest.fixture(scope="module")
def driver(endpoint: str) -> Iterator[Any]:
    """lab_sim's driver, headless, as fast as it goes."""
    from kinema.drivers.mujoco import MujocoDriver, MujocoDriverSettings
    from kinema.transport import open_session

    session = open_session(endpoint)
    sim = MujocoDriver(session, MujocoDriverSettings.from_config("lab_sim", sim_speed=math.inf))
    sim.start()
    yield sim
    sim.stop()
    session.close()


@pytest.fixture(scope="module")
def registry() -> BehaviorRegistry:
    host = BehaviorHost(["kinema::CoreBehaviorsLoader", "kinema::MujocoBehaviorsLoader"])
    host.load().raise_for_errors()
    return host.registry


@pytest.fixture(scope="module")
def context(endpoint: str, driver: Any) -> Iterator[BehaviorContext]:
    """A context like the agent's: transport node, sim clock from /clock, lab_sim's model and config."""
    from kinema.config import resolve_config
    from kinema.motion import RobotDescription
    from kinema.runtime.sim_clock import SimClock
    from kinema.transport import Node, open_session

    session = open_session(endpoint)
    node = Node(session, "behavior_sim_tests")
    clock = SimClock()
    node.create_subscription("rosgraph_msgs/msg/Clock", "/clock", clock.on_clock_message)
    ctx = BehaviorContext(
        node,
        clock=clock,
        robot_model=RobotDescription.lab_sim().load_model(),
        config=resolve_config("lab_sim"),
    )
    yield ctx
    ctx.close()
    session.close()


@pytest.fixture
def behavior(registry: BehaviorRegistry) -> Any:
    return lambda behavior_id: registry[behavior_id].cls
