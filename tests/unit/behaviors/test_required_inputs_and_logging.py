"""Required inputs are reported all at once; toasts carry the behavior, node path and plugin."""

from __future__ import annotations

import pytest

from kinema.behaviors import BehaviorContext, LogLevel, NodeStatus, SyncBehavior, input_port
from kinema.errors import ObjectiveError
from kinema.testing import build_tree, registry_of, tick_behavior


class NeedsThree(SyncBehavior):
    """Needs x, y and z."""

    subcategory = "Tests"

    @classmethod
    def provided_ports(cls):
        return [input_port("x", int), input_port("y", int), input_port("z", int, 3)]

    def tick(self) -> NodeStatus:
        x, y, z = self.get_required_inputs("x", "y", "z")
        self.logger.publish_info(f"{x + y + z}")
        self.logger.publish_warn("careful")
        self.logger.publish_failure("not really")
        return NodeStatus.SUCCESS


def test_one_error_names_every_missing_port() -> None:
    tree = build_tree(
        '<root BTCPP_format="4"><BehaviorTree ID="T">'
        '<NeedsThree name="sum" y="{nothing}"/></BehaviorTree></root>',
        behaviors=[NeedsThree],
    )
    with pytest.raises(ObjectiveError) as caught:
        tree.tick_once()
    message = str(caught.value)
    assert "Failed to get required values from input data ports" in message
    assert "'x'" in message and "'y'" in message and "'z'" not in message
    assert "sum" in message


def test_messages_reach_the_sink_with_level_behavior_path_and_plugin() -> None:
    context = BehaviorContext()
    received = []
    context.log_sink.subscribe(received.append)
    registry = registry_of([NeedsThree], plugin="tests::Loader")
    tree = registry.create_factory(context).create_tree_from_text(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence name="main">'
        '<NeedsThree name="adder" x="1" y="2"/></Sequence></BehaviorTree></root>'
    )
    assert tree.tick_once() == NodeStatus.SUCCESS
    assert [(m.level, m.text) for m in received] == [
        (LogLevel.INFO, "6"),
        (LogLevel.WARN, "careful"),
        (LogLevel.FAILURE, "not really"),
    ]
    assert {(m.behavior_id, m.node_name, m.plugin) for m in received} == {
        ("NeedsThree", "adder", "tests::Loader")
    }
    assert received[0].node_path.endswith("adder")


def test_tick_behavior_reports_toasts_and_the_metadata_comes_from_the_class() -> None:
    run = tick_behavior(NeedsThree, {"x": 1, "y": 1})
    assert run.toasts == ["5", "careful", "not really"]
    assert NeedsThree.metadata() == {"subcategory": "Tests", "description": "Needs x, y and z."}


def test_a_description_from_the_docstring_shows_its_literals_as_the_cli_writes_them() -> None:
    class Adds(SyncBehavior):
        """Adds ``int_1`` and
        ``int_2``.

        The rest of the docstring is not the description.
        """

    assert Adds.metadata()["description"] == "Adds `int_1` and `int_2`."


def test_the_robot_model_is_built_once_on_first_use() -> None:
    calls = []

    def build_model() -> str:
        calls.append(1)
        return "model"

    context = BehaviorContext(robot_model=build_model)
    assert calls == []
    assert context.robot_model == "model" and context.robot_model == "model"
    assert calls == [1]


def test_an_offline_context_says_why_a_transport_behavior_cannot_run() -> None:
    with pytest.raises(ObjectiveError, match="needs the transport"):
        BehaviorContext.offline().require_node("MyServiceClient")
