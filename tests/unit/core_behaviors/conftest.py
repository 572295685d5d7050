"""Fixtures: the bundled core and MuJoCo behaviors, a private in-process network, the lab_sim model."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from kinema.behaviors import BehaviorContext
from kinema.plugins import BehaviorHost, BehaviorRegistry


@pytest.fixture(scope="session")
def registry() -> BehaviorRegistry:
    """The behaviors of ``kinema::CoreBehaviorsLoader`` and ``kinema::MujocoBehaviorsLoader``."""
    host = BehaviorHost(["kinema::CoreBehaviorsLoader", "kinema::MujocoBehaviorsLoader"])
    report = host.load()
    report.raise_for_errors()
    return host.registry


@pytest.fixture(scope="session")
def behavior(registry: BehaviorRegistry) -> Any:
    """``behavior("RetrieveWaypoint")``: the registered class of a behavior ID."""
    return lambda behavior_id: registry[behavior_id].cls


@pytest.fixture
def node() -> Iterator[Any]:
    """A transport node on a private in-process network."""
    from kinema.transport import Node, open_session

    session = open_session([])
    try:
        yield Node(session, "core_behavior_tests")
    finally:
        session.close()


@pytest.fixture(scope="session")
def lab_sim_model() -> Any:
    """lab_sim's robot model (loaded once: pinocchio parsing takes a moment)."""
    from kinema.motion import RobotDescription

    return RobotDescription.lab_sim().load_model()


@pytest.fixture
def context(node: Any, lab_sim_model: Any) -> Iterator[BehaviorContext]:
    """A behavior context with the transport node and lab_sim's model and config."""
    from kinema.config import resolve_config

    ctx = BehaviorContext(node, robot_model=lab_sim_model, config=resolve_config("lab_sim"))
    try:
        yield ctx
    finally:
        ctx.close()
