"""A behavior that raises fails its objective with one message naming plugin, behavior, node path and line;
the registry (and so the runtime) keeps serving the next objective."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeExecutionError, NodeStatus
from kinema.plugins import BehaviorHost

SOURCE = """
from kinema.behaviors import AsyncBehavior, NodeStatus, ServiceClientBehavior, SyncBehavior, input_port


class Healthy(SyncBehavior):
    def tick(self):
        return NodeStatus.SUCCESS


class BadTick(SyncBehavior):
    def tick(self):
        values = {}
        return values["missing"]


class BadWork(AsyncBehavior):
    async def do_work(self):
        raise ValueError("the work went wrong")


class BadResponse(ServiceClientBehavior["example_interfaces/srv/AddTwoInts"]):
    @classmethod
    def provided_ports(cls):
        return [input_port("service_name", str, "/add_two_ints")]

    def create_request(self):
        return {"a": 1, "b": 2}

    def process_response(self, response):
        return response.no_such_field > 0
"""
CLASSES = ["Healthy", "BadTick", "BadWork", "BadResponse"]


def _tree(behavior: str) -> str:
    return (
        '<root BTCPP_format="4"><BehaviorTree ID="Main"><Sequence name="steps">'
        f'<Healthy/><{behavior} name="culprit"/></Sequence></BehaviorTree></root>'
    )


def _line_of(path: Path, text: str) -> int:
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if text in line)


@pytest.mark.parametrize(
    ("behavior", "stage", "raising_line", "error_text"),
    [
        ("BadTick", "tick", 'return values["missing"]', "KeyError"),
        ("BadWork", "do_work", 'raise ValueError("the work went wrong")', "the work went wrong"),
        ("BadResponse", "process_response", "return response.no_such_field > 0", "AttributeError"),
    ],
)
def test_a_raising_behavior_fails_the_objective_with_plugin_behavior_path_and_line(
    workspace: Path, write_package, node: Any, behavior: str, stage: str, raising_line: str, error_text: str
) -> None:
    package = write_package("faulty", SOURCE, CLASSES)
    node.create_service("example_interfaces/srv/AddTwoInts", "/add_two_ints", lambda r: {"sum": r.a + r.b})
    host = BehaviorHost(["faulty::TestLoader"], workspace)
    assert host.load().ok
    factory = host.registry.create_factory(BehaviorContext(node))
    tree = factory.create_tree_from_text(_tree(behavior))
    with pytest.raises(NodeExecutionError) as caught:
        tree.tick_while_running(0.005)
    message = str(caught.value)
    module = package / "faulty" / "behaviors.py"
    assert "culprit" in caught.value.node_path
    assert f"behavior '{behavior}' of plugin 'faulty::TestLoader'" in message
    assert f"in {stage}" in message and error_text in message
    assert f"{module}:{_line_of(module, raising_line)}" in message

    # The next objective, built from the same registry, runs normally.
    again = host.registry.create_factory(BehaviorContext(node)).create_tree_from_text(_tree("Healthy"))
    assert again.tick_while_running(0.005) == NodeStatus.SUCCESS
