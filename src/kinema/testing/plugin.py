"""Kinema's pytest plugin (entry point ``pytest11: kinema``): fixtures for behavior authors.

* ``tick_behavior(cls, inputs, node=...)`` → :class:`~kinema.testing.BehaviorRun` (status, outputs, toasts);
* ``build_tree(xml, registry=..., behaviors=[...], node=...)`` → a :class:`~kinema.bt.Tree`;
* ``run_objective(xml_or_path, registry=..., node=...)`` → status, blackboard values and toasts;
* ``kinema_node``: a transport node on a private in-process network (no router, no other process);
* ``publish_repeatedly(node, type, topic, message)``: a context manager publishing in the background;
* ``kinema_runtime(config, workspace=..., objective_dirs=[...])``: the agent running in this process on a
  private network, with an SDK client (``.client.execute("My Objective")``); stopped after the test;
* ``package_registry``: the behaviors of the behavior package under test, loaded by path as the runtime
  loads them (the package is the folder holding the ``pyproject.toml`` pytest runs from).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

if TYPE_CHECKING:
    from kinema.testing import harness

# The plugin loads in every pytest run of an environment where Kinema is installed, so Kinema itself is
# imported only when a fixture is used.


@pytest.fixture
def tick_behavior() -> Callable[..., harness.BehaviorRun]:
    """Run one behavior class to completion: ``tick_behavior(MyBehavior, {"int_1": 2}, node=kinema_node)``."""
    from kinema.testing import harness

    return harness.tick_behavior


@pytest.fixture
def build_tree() -> Callable[..., Any]:
    """Build a tree from XML: ``build_tree(xml, behaviors=[MyBehavior])`` or ``registry=package_registry``."""
    from kinema.testing import harness

    return harness.build_tree


@pytest.fixture
def run_objective() -> Callable[..., harness.ObjectiveRunResult]:
    """Run an objective (XML text or a file) to completion with the given registry or behaviors."""
    from kinema.testing import harness

    return harness.run_objective


@pytest.fixture
def publish_repeatedly() -> Callable[..., Any]:
    """``with publish_repeatedly(node, "std_msgs/msg/String", "/chatter", {"data": "hi"}): ...``."""
    from kinema.testing import harness

    return harness.publish_repeatedly


@pytest.fixture
def kinema_session() -> Iterator[Any]:
    """A transport session of its own (peer, loopback, no router): tests never see other processes."""
    from kinema.transport import open_session

    session = open_session([])
    try:
        yield session
    finally:
        session.close()


@pytest.fixture
def kinema_node(kinema_session: Any) -> Iterator[Any]:
    """A transport node on :func:`kinema_session`; behaviors and test servers share it."""
    from kinema.transport import Node

    node = Node(kinema_session, "kinema_test")
    try:
        yield node
    finally:
        node.close()


@pytest.fixture(scope="session")
def package_registry(request: pytest.FixtureRequest) -> Any:
    """The registry of the behavior package under test (its ``pyproject.toml`` is pytest's rootdir)."""
    from kinema.testing import harness

    root = Path(request.config.rootpath)
    return harness.load_behavior_package(root)


@pytest.fixture
def kinema_runtime() -> Iterator[Callable[..., Any]]:
    """Start a runtime in-process: ``runtime = kinema_runtime("my_config", workspace=ws)``; see
    :func:`kinema.testing.runtime_in_process` for the arguments. Every runtime started is stopped after
    the test."""
    import contextlib

    from kinema.testing import harness

    with contextlib.ExitStack() as stack:

        def start(*args: Any, **kwargs: Any) -> Any:
            return stack.enter_context(harness.runtime_in_process(*args, **kwargs))

        yield start
