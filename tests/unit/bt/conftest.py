"""Fixtures for the behavior-tree engine tests: a factory with counting test nodes."""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable

import pytest

from kinema.bt import BehaviorTreeFactory, Blackboard, NodeStatus, StatefulActionNode, Tree, TreeNode

S, F, R = NodeStatus.SUCCESS, NodeStatus.FAILURE, NodeStatus.RUNNING


def wrap(body: str, tree_id: str = "Main") -> str:
    """A one-tree document around ``body``."""
    return f'<root BTCPP_format="4"><BehaviorTree ID="{tree_id}">{body}</BehaviorTree></root>'


class Bench:
    """A factory plus per-ID tick counters for scripted test nodes."""

    def __init__(self) -> None:
        self.factory = BehaviorTreeFactory()
        self.ticks: Counter[str] = Counter()
        self.halts: Counter[str] = Counter()

    def action(self, node_id: str, *results: NodeStatus) -> None:
        """A sync action returning ``results`` in turn (the last one repeats); default SUCCESS."""
        self._simple(node_id, results or (S,), self.factory.register_simple_action)

    def condition(self, node_id: str, *results: NodeStatus) -> None:
        """A condition returning ``results`` in turn (may include RUNNING)."""
        self._simple(node_id, results or (S,), self.factory.register_simple_condition)

    def _simple(self, node_id: str, results: tuple[NodeStatus, ...], register: Callable) -> None:
        def tick(node: TreeNode) -> NodeStatus:
            self.ticks[node_id] += 1
            return results[min(self.ticks[node_id], len(results)) - 1]

        register(node_id, tick)

    def stateful(self, node_id: str, running_ticks: int, result: NodeStatus = S) -> None:
        """RUNNING for ``running_ticks`` ticks after the first (-1: forever), then ``result``."""
        bench = self

        class Worker(StatefulActionNode):
            def on_start(self) -> NodeStatus:
                bench.ticks[node_id] += 1
                self.n = 0
                return result if running_ticks == 0 else R

            def on_running(self) -> NodeStatus:
                bench.ticks[node_id] += 1
                self.n += 1
                return result if 0 <= running_ticks <= self.n else R

            def on_halted(self) -> None:
                bench.halts[node_id] += 1

        self.factory.register_node_type(Worker, node_id)

    def tree(self, body: str, blackboard: Blackboard | None = None) -> Tree:
        """Build a one-tree document around ``body``."""
        return self.factory.create_tree_from_text(wrap(body), blackboard)

    def xml(self, xml: str, blackboard: Blackboard | None = None) -> Tree:
        """Build a whole document."""
        return self.factory.create_tree_from_text(xml, blackboard)


@pytest.fixture
def bench() -> Bench:
    return Bench()
