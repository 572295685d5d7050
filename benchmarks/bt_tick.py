"""Tick speed of kinema.bt against py_trees on the same tree structures, measured in one run.

Two structures, built for both engines:

* a Sequence of 1000 ``AlwaysSuccess`` leaves;
* a mixed tree of about 1000 nodes: groups under a Sequence, each a reactive sequence holding a
  script condition, an inverted failure, a fallback, a script that increments a blackboard counter
  and a subtree (py_trees has no subtrees or scripts: the equivalents are a nested composite and
  behaviours reading/writing its blackboard).

It prints ticks per second for each engine, the ratio, and the time Kinema needs to build the
1000-node Sequence from XML. Targets (issue 2): ratio >= 20x, >= 2,500 ticks/s on the Sequence,
build < 50 ms. Run: ``python benchmarks/bt_tick.py [--seconds S]``.
"""

from __future__ import annotations

import argparse
import operator
import statistics
import time
from collections.abc import Callable

import py_trees

from kinema.bt import BehaviorTreeFactory, Blackboard

N_LEAVES = 1000
GROUP_SIZE = 11
N_GROUPS = (N_LEAVES - 1) // GROUP_SIZE + 1


def sequence_xml(n: int = N_LEAVES) -> str:
    """A Sequence with ``n`` AlwaysSuccess children."""
    leaves = "".join("<AlwaysSuccess/>" for _ in range(n))
    return (
        f'<root BTCPP_format="4"><BehaviorTree ID="Main"><Sequence>{leaves}</Sequence></BehaviorTree></root>'
    )


def mixed_xml(groups: int = N_GROUPS) -> str:
    """The mixed structure: ``groups`` reactive groups of 11 nodes under a Sequence."""
    group = (
        "<ReactiveSequence>"
        '<ScriptCondition code="counter &gt;= 0"/>'
        "<Inverter><AlwaysFailure/></Inverter>"
        "<Fallback><AlwaysFailure/><AlwaysSuccess/></Fallback>"
        '<Script code="counter += 1"/>'
        '<SubTree ID="Leaf"/>'
        "</ReactiveSequence>"
    )
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Main">'
        f'<BehaviorTree ID="Main"><Sequence>{group * groups}</Sequence></BehaviorTree>'
        '<BehaviorTree ID="Leaf"><ForceSuccess><AlwaysFailure/></ForceSuccess></BehaviorTree>'
        "</root>"
    )


class _Increment(py_trees.behaviour.Behaviour):
    """py_trees equivalent of ``<Script code="counter += 1"/>``."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.bb = self.attach_blackboard_client()
        self.bb.register_key("counter", access=py_trees.common.Access.WRITE)

    def update(self) -> py_trees.common.Status:
        self.bb.counter += 1
        return py_trees.common.Status.SUCCESS


def py_trees_sequence(n: int = N_LEAVES) -> py_trees.behaviour.Behaviour:
    """py_trees Sequence of ``n`` Success behaviours."""
    children = [py_trees.behaviours.Success(name=f"s{i}") for i in range(n)]
    return py_trees.composites.Sequence(name="root", memory=True, children=children)


def py_trees_mixed(groups: int = N_GROUPS) -> py_trees.behaviour.Behaviour:
    """py_trees version of :func:`mixed_xml` (same node count and control flow)."""
    py_trees.blackboard.Blackboard.clear()
    writer = py_trees.blackboard.Client(name="setup")
    writer.register_key("counter", access=py_trees.common.Access.WRITE)
    writer.counter = 0
    group_nodes = []
    for g in range(groups):
        check = py_trees.behaviours.CheckBlackboardVariableValue(
            name=f"check{g}",
            check=py_trees.common.ComparisonExpression(variable="counter", value=0, operator=operator.ge),
        )
        inverted = py_trees.decorators.Inverter(
            name=f"inv{g}", child=py_trees.behaviours.Failure(name=f"f{g}")
        )
        fallback = py_trees.composites.Selector(
            name=f"fb{g}",
            memory=False,
            children=[py_trees.behaviours.Failure(name=f"fa{g}"), py_trees.behaviours.Success(name=f"su{g}")],
        )
        subtree = py_trees.composites.Sequence(
            name=f"sub{g}",
            memory=False,
            children=[
                py_trees.decorators.FailureIsSuccess(
                    name=f"fs{g}", child=py_trees.behaviours.Failure(name=f"x{g}")
                )
            ],
        )
        group_nodes.append(
            py_trees.composites.Sequence(
                name=f"g{g}",
                memory=False,
                children=[check, inverted, fallback, _Increment(f"inc{g}"), subtree],
            )
        )
    return py_trees.composites.Sequence(name="root", memory=True, children=group_nodes)


def ticks_per_second(tick: Callable[[], object], seconds: float) -> float:
    """Best of three runs of ``seconds / 3`` each (the least disturbed by other processes)."""
    rates = []
    for _ in range(3):
        count = 0
        start = time.perf_counter()
        deadline = start + seconds / 3
        while True:
            for _ in range(10):
                tick()
            count += 10
            now = time.perf_counter()
            if now >= deadline:
                break
        rates.append(count / (now - start))
    return max(rates)


def build_ms(xml: str, repeats: int = 10) -> float:
    """Median time to load ``xml`` and build its tree with a fresh factory, in ms."""
    times = []
    for _ in range(repeats):
        factory = BehaviorTreeFactory()
        start = time.perf_counter()
        factory.create_tree_from_text(xml)
        times.append((time.perf_counter() - start) * 1000.0)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=3.0, help="time spent per engine and structure")
    args = parser.parse_args()

    factory = BehaviorTreeFactory()
    seq_tree = factory.create_tree_from_text(sequence_xml())
    bb = Blackboard.create()
    bb.set("counter", 0)
    mixed_tree = BehaviorTreeFactory().create_tree_from_text(mixed_xml(), bb)
    pt_seq = py_trees_sequence()
    pt_mixed = py_trees_mixed()

    rows = []
    for label, kinema_tree, pt_root in (
        (f"Sequence of {N_LEAVES} AlwaysSuccess", seq_tree, pt_seq),
        ("mixed tree", mixed_tree, pt_mixed),
    ):
        n_kinema = len(kinema_tree)
        n_pt = sum(1 for _ in pt_root.iterate())
        kinema_rate = ticks_per_second(kinema_tree.tick_once, args.seconds)
        pt_rate = ticks_per_second(pt_root.tick_once, args.seconds)
        rows.append((label, n_kinema, n_pt, kinema_rate, pt_rate))

    print(f"{'structure':<34} {'nodes':>11} {'kinema t/s':>11} {'py_trees t/s':>13} {'ratio':>7}")
    for label, n_kinema, n_pt, kinema_rate, pt_rate in rows:
        nodes = f"{n_kinema}/{n_pt}"
        print(f"{label:<34} {nodes:>11} {kinema_rate:>11.0f} {pt_rate:>13.0f} {kinema_rate / pt_rate:>6.1f}x")
    build = build_ms(sequence_xml())
    print(f"build {N_LEAVES}-node Sequence from XML: {build:.1f} ms (median of 10)")
    seq_rate, seq_ratio = rows[0][3], rows[0][3] / rows[0][4]
    print(
        "targets: ratio >= 20x: {}, >= 2500 ticks/s: {}, build < 50 ms: {}".format(
            "met" if seq_ratio >= 20 else "MISSED",
            "met" if seq_rate >= 2500 else "MISSED",
            "met" if build < 50 else "MISSED",
        )
    )
    print(f"counter after the mixed runs: {bb.get('counter')} (the scripts really ran)")


if __name__ == "__main__":
    main()
