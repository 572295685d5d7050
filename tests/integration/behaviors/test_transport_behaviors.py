"""The transport base classes and the bundled tutorial behaviors, against servers on an in-process network."""

from __future__ import annotations

import threading
from typing import Any

import pytest

from kinema.behaviors import (
    ActionClientBehavior,
    BehaviorContext,
    GetMessageFromTopicBehavior,
    PublishToTopicBehavior,
    input_port,
    output_port,
)
from kinema.bt import NodeStatus
from kinema.errors import ObjectiveError, PluginError
from kinema.plugins import BehaviorHost
from kinema.testing import build_tree, publish_repeatedly, run_objective, tick_behavior

TUTORIAL = """
<root BTCPP_format="4" main_tree_to_execute="Tutorial">
  <BehaviorTree ID="Tutorial">
    <Sequence>
      <Action ID="MyBehavior" int_1="2" int_2="3" int_out="{sum}"/>
      <Action ID="MyServiceClient" addend1="{sum}" addend2="37" result="{result}"/>
    </Sequence>
  </BehaviorTree>
</root>
"""


def test_the_bundled_tutorial_behaviors_add_locally_then_through_the_service(node: Any) -> None:
    node.create_service("example_interfaces/srv/AddTwoInts", "/add_two_ints", lambda r: {"sum": r.a + r.b})
    host = BehaviorHost(["kinema::ExampleBehaviorsLoader"])
    assert host.load().ok
    run = run_objective(TUTORIAL, registry=host.registry, node=node)
    assert run.status == NodeStatus.SUCCESS
    assert (run.blackboard["sum"], run.blackboard["result"]) == (5, 42)
    assert run.toasts == ["Sum: 42"]
    assert run.messages[0].plugin == "kinema::ExampleBehaviorsLoader"


def test_the_service_client_fails_with_a_toast_when_no_server_answers(node: Any) -> None:
    host = BehaviorHost(["kinema::ExampleBehaviorsLoader"])
    host.load()
    cls = host.registry["MyServiceClient"].cls
    quick = type("QuickServiceClient", (cls,), {"get_response_timeout": lambda self: 0.2})
    run = tick_behavior(quick, {"service_name": "/nobody_home"}, node=node)
    assert run.status == NodeStatus.FAILURE
    assert "Failed to call service /nobody_home" in run.toasts[-1]


class Fibonacci(ActionClientBehavior["example_interfaces/action/Fibonacci"]):
    @classmethod
    def provided_ports(cls):
        return [
            input_port("action_name", str, "/fibonacci"),
            input_port("order", int, 4),
            output_port("sequence", list[int], "{sequence}"),
        ]

    def create_goal(self) -> dict[str, int]:
        return {"order": self.get_input("order")}

    def process_result(self, result: Any) -> bool:
        self.set_output("sequence", [int(n) for n in result.result.sequence])
        return result.succeeded


class _Server:
    def __init__(self, node: Any, *, hold: bool = False, accept: bool = True) -> None:
        self.hold = hold
        self.cancelled = threading.Event()
        self.server = node.create_action_server(
            "example_interfaces/action/Fibonacci",
            "/fibonacci",
            self.execute,
            goal_callback=lambda goal: accept,
        )

    def execute(self, handle: Any) -> None:
        sequence = [0, 1, 1, 2, 3, 5, 8][: handle.goal.order]
        while self.hold and not handle.is_cancel_requested:
            handle.cancel_requested_event.wait(0.01)
        if handle.is_cancel_requested:
            self.cancelled.set()
            handle.canceled({"sequence": sequence})
        else:
            handle.succeed({"sequence": sequence})


def test_the_action_client_gets_the_result(node: Any) -> None:
    _Server(node)
    run = tick_behavior(Fibonacci, {"order": 5}, node=node)
    assert (run.status, run.outputs["sequence"]) == (NodeStatus.SUCCESS, [0, 1, 1, 2, 3])


def test_an_action_client_typed_by_its_interface_classes_gets_typed_feedback_and_result(node: Any) -> None:
    from kinema.interfaces.typed import Fibonacci as Fib
    from kinema.transport import GoalResult

    class TypedFibonacci(ActionClientBehavior[Fib.Goal, Fib.Result, Fib.Feedback]):
        @classmethod
        def provided_ports(cls):
            return [
                input_port("action_name", str, "/fibonacci"),
                output_port("sequence", list[int], "{sequence}"),
            ]

        def create_goal(self) -> Fib.Goal:
            return Fib.Goal(order=4)

        def process_result(self, result: GoalResult[Fib.Result]) -> bool:
            assert isinstance(result.result, Fib.Result)
            self.set_output("sequence", [int(n) for n in result.result.sequence])
            return result.succeeded

    assert TypedFibonacci.action_type == "example_interfaces/action/Fibonacci"
    _Server(node)
    run = tick_behavior(TypedFibonacci, node=node)
    assert (run.status, run.outputs["sequence"]) == (NodeStatus.SUCCESS, [0, 1, 1, 2])


def test_feedback_that_arrives_after_the_result_is_not_processed(node: Any, monkeypatch) -> None:
    # Feedback travels apart from the result and can be dispatched after it (a loaded machine showed it: the
    # generated action client's last toast was its progress, not its result). Hold the last feedback until
    # the result is being processed, then deliver it: the behavior must not report progress after that.
    from kinema.transport.action import ClientGoalHandle

    first_delivered, result_started, late_delivered = threading.Event(), threading.Event(), threading.Event()
    deliver = ClientGoalHandle._on_feedback

    def held(handle: Any, feedback: Any) -> None:
        if list(feedback.sequence) == [99]:
            result_started.wait(10.0)
            deliver(handle, feedback)
            late_delivered.set()
        else:
            deliver(handle, feedback)
            first_delivered.set()

    monkeypatch.setattr(ClientGoalHandle, "_on_feedback", held)
    seen: list[str] = []

    class Following(Fibonacci):
        def process_feedback(self, feedback: Any) -> None:
            seen.append(f"feedback {list(map(int, feedback.sequence))}")

        def process_result(self, result: Any) -> bool:
            seen.append("result")
            result_started.set()
            assert late_delivered.wait(10.0), "the held feedback never reached the client"
            return super().process_result(result)

    def execute(handle: Any) -> None:
        handle.publish_feedback({"sequence": [0]})
        first_delivered.wait(10.0)  # feedback that comes before the result is processed
        handle.publish_feedback({"sequence": [99]})
        handle.succeed({"sequence": [0, 1]})

    node.create_action_server("example_interfaces/action/Fibonacci", "/fibonacci", execute)
    run = tick_behavior(Following, {"order": 2}, node=node)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    assert seen == ["feedback [0]", "result"]


def test_a_rejected_goal_fails_with_a_toast(node: Any) -> None:
    _Server(node, accept=False)
    run = tick_behavior(Fibonacci, node=node)
    assert run.status == NodeStatus.FAILURE
    assert "rejected" in run.toasts[-1]


def test_halting_the_action_client_cancels_the_goal_on_the_server(node: Any) -> None:
    server = _Server(node, hold=True)
    tree = build_tree(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Fibonacci/></BehaviorTree></root>',
        behaviors=[Fibonacci],
        node=node,
    )
    for _ in range(500):
        tree.tick_once()
        if server.server.goals():
            break
        tree.sleep(0.01)
    tree.halt_tree()
    assert server.cancelled.wait(5.0)


class TakeString(GetMessageFromTopicBehavior["std_msgs/msg/String"]):
    pass


class SayString(PublishToTopicBehavior["std_msgs/msg/String"]):
    pass


def test_get_message_from_topic_takes_the_next_message_or_times_out(node: Any) -> None:
    with publish_repeatedly(node, "std_msgs/msg/String", "/words", {"data": "hello"}):
        run = tick_behavior(TakeString, {"topic_name": "/words"}, node=node)
    assert (run.status, run.outputs["message_out"].data) == (NodeStatus.SUCCESS, "hello")
    run = tick_behavior(TakeString, {"topic_name": "/silent", "timeout": 0.1}, node=node)
    assert run.status == NodeStatus.FAILURE and "No message on /silent" in run.toasts[-1]


def test_publish_to_topic_sends_a_dict_as_the_message(node: Any) -> None:
    received: list[str] = []
    arrived = threading.Event()
    node.create_subscription(
        "std_msgs/msg/String", "/said", lambda message: (received.append(message.data), arrived.set())
    )
    run = tick_behavior(SayString, {"topic": "/said", "message": {"data": "hi"}}, node=node)
    assert run.status == NodeStatus.SUCCESS
    assert arrived.wait(5.0) and received == ["hi"]


def test_an_interface_type_must_be_a_ros_type_name() -> None:
    with pytest.raises(PluginError, match="pkg/action/Name"):
        ActionClientBehavior["not a type"]
    with pytest.raises(PluginError, match="pkg/msg/Name"):
        GetMessageFromTopicBehavior["example_interfaces/srv/AddTwoInts"]


def test_a_transport_behavior_without_a_node_fails_with_an_explanation() -> None:
    context = BehaviorContext()
    with pytest.raises(ObjectiveError, match="needs the transport"):
        tick_behavior(TakeString, {"topic_name": "/x"}, context=context)
