"""AsyncBehavior: work runs off the tick thread, the tree stays responsive, halting stops the work."""

from __future__ import annotations

import asyncio
import threading

import pytest

from kinema.behaviors import AsyncBehavior, input_port, output_port
from kinema.bt import NodeStatus
from kinema.errors import ObjectiveError
from kinema.testing import build_tree, tick_behavior


class Adder(AsyncBehavior):
    """Adds a and b."""

    @classmethod
    def provided_ports(cls):
        return [input_port("a", int, 0), input_port("b", int, 0), output_port("sum", int, "{sum}")]

    async def do_work(self) -> bool:
        a, b = self.get_required_inputs("a", "b")
        await asyncio.sleep(0.01)
        self.set_output("sum", a + b)
        return True


class ThreadedAdder(Adder):
    def do_work(self) -> bool:
        a, b = self.get_required_inputs("a", "b")
        self.set_output("sum", a + b)
        return a + b >= 0


def test_a_coroutine_runs_off_the_tick_thread_and_its_outputs_arrive() -> None:
    run = tick_behavior(Adder, {"a": 2, "b": 40})
    assert (run.status, run.outputs["sum"]) == (NodeStatus.SUCCESS, 42)
    assert run.ticks >= 2  # RUNNING first, the tree is ticked again while the work runs


def test_a_plain_function_runs_in_a_worker_and_false_means_failure() -> None:
    assert tick_behavior(ThreadedAdder, {"a": 1, "b": 1}).outputs["sum"] == 2
    run = tick_behavior(ThreadedAdder, {"a": -5, "b": 1})
    assert (run.status, run.outputs["sum"]) == (NodeStatus.FAILURE, -4)


class Forever(AsyncBehavior):
    started = threading.Event()
    cancelled = threading.Event()
    halted = threading.Event()

    async def do_work(self) -> bool:
        type(self).started.set()
        try:
            await asyncio.sleep(3600)
        except asyncio.CancelledError:
            type(self).cancelled.set()
            raise
        return True

    def do_halt(self) -> None:
        type(self).halted.set()


class ForeverInAThread(AsyncBehavior):
    started = threading.Event()
    stopped = threading.Event()

    def do_work(self) -> bool:
        type(self).started.set()
        while not self.stop_requested():
            threading.Event().wait(0.005)
        type(self).stopped.set()
        return False


def test_halting_cancels_a_coroutine_and_calls_do_halt() -> None:
    tree = build_tree(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Forever/></BehaviorTree></root>', behaviors=[Forever]
    )
    assert tree.tick_once() == NodeStatus.RUNNING
    assert Forever.started.wait(5)
    tree.halt_tree()
    assert Forever.halted.is_set()
    assert Forever.cancelled.wait(5)
    assert tree.root_node.status == NodeStatus.IDLE


def test_halting_asks_a_plain_function_to_stop() -> None:
    tree = build_tree(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><ForeverInAThread/></BehaviorTree></root>',
        behaviors=[ForeverInAThread],
    )
    assert tree.tick_once() == NodeStatus.RUNNING
    assert ForeverInAThread.started.wait(5)
    tree.halt_tree()
    assert ForeverInAThread.stopped.wait(5)


class ReturnsNothing(AsyncBehavior):
    async def do_work(self):
        return None


def test_do_work_must_say_success_or_failure() -> None:
    with pytest.raises(ObjectiveError, match=r"do_work\(\) returned None; return True .* or False"):
        tick_behavior(ReturnsNothing)


def test_the_tree_can_run_the_same_behavior_again() -> None:
    tree = build_tree(
        '<root BTCPP_format="4"><BehaviorTree ID="T">'
        '<Adder a="{a}" b="3" sum="{sum}"/></BehaviorTree></root>',
        behaviors=[Adder],
    )
    for a in (1, 2, 3):
        tree.root_blackboard.set("a", a)
        assert tree.tick_while_running() == NodeStatus.SUCCESS
        assert tree.root_blackboard.get("sum") == a + 3


class BadHalt(Forever):
    def do_halt(self) -> None:
        raise RuntimeError("cannot let go")


def test_a_raising_do_halt_is_reported_and_the_work_still_stops() -> None:
    from kinema.behaviors import BehaviorContext

    context = BehaviorContext()
    messages = []
    context.log_sink.subscribe(messages.append)
    Forever.cancelled.clear()
    tree = build_tree(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><BadHalt/></BehaviorTree></root>',
        behaviors=[BadHalt],
        context=context,
    )
    assert tree.tick_once() == NodeStatus.RUNNING
    tree.halt_tree()
    assert Forever.cancelled.wait(5)
    (message,) = messages
    assert "behavior 'BadHalt'" in message.text and "do_halt" in message.text
    assert "cannot let go" in message.text and "test_async_behavior.py" in message.text
