"""Tick and build speed of kinema.bt against the real BehaviorTree.CPP and py_trees, in one run.

BT.CPP is the ``behaviortreepy`` bindings (BT.CPP 4.8.2 in C++; one Python call ticks the whole
tree). The same XML runs in Kinema and BT.CPP; py_trees gets hand-built equivalents where it has
them. Structures:

* ``sequence`` - a Sequence of 1000 ``AlwaysSuccess`` leaves;
* ``mixed`` - about 1000 nodes: groups under a Sequence, each a ReactiveSequence holding a
  ScriptCondition, an inverted failure, a Fallback, a Script incrementing a blackboard counter
  and a SubTree;
* ``pick_place`` - shaped like lab_sim's "3 Waypoints Pick and Place": nested SubTrees with
  remapped ports (``Move to Waypoint`` -> ``Move to Joint State``, grippers) under
  KeepRunningUntilFailure; the robot behaviors are a registered action ``Work`` that succeeds
  (a Python callback in both engines), with Scripts passing values as the real ones pass poses;
* building each of them from XML, with a new factory each time and again with the same factory
  (which Kinema serves from its cache of parsed, verified and compiled documents).

Kinema is also measured "as objectives run": with what the runtime attaches on the tick thread
(:class:`ObjectiveObservers`: the status recorder reading the tree's transition log after every
tick, the agent's node status messages built and serialised, the blackboard snapshot at 10 Hz and
the run's ``.btlog`` recording). BT.CPP is measured the same way with what a BT.CPP application
attaches to record a run: its ``FileLogger2`` (the ``.btlog`` writer, which takes every transition
through a status callback and writes from its own thread). Rates are ticks per CPU second
(``time.process_time``, every thread of the process), median of ``--rounds`` rounds; ratios are
Kinema's time over BT.CPP's (lower is better; 1.0 = parity).
Targets (issue 17): sequence <= 1.0x, mixed <= 1.5x, XML build <= 2x, observers <= +20 %.
Run: ``python benchmarks/bt_tick.py [--seconds S] [--rounds N] [--profile STRUCTURE]``.
"""

from __future__ import annotations

import argparse
import cProfile
import operator
import pstats
import statistics
import time
from collections.abc import Callable
from typing import Any

N_LEAVES = 1000
GROUP_SIZE = 11
N_GROUPS = (N_LEAVES - 1) // GROUP_SIZE + 1


def sequence_xml(n: int = N_LEAVES) -> str:
    """A Sequence with ``n`` AlwaysSuccess children."""
    leaves = "".join("<AlwaysSuccess/>" for _ in range(n))
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Main">'
        f'<BehaviorTree ID="Main"><Sequence>{leaves}</Sequence></BehaviorTree></root>'
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


def pick_place_xml() -> str:
    """A tree shaped like lab_sim's pick and place: SubTrees three deep, remapped ports, a loop."""
    move_to_joint_state = (
        '<BehaviorTree ID="Move to Joint State"><Sequence name="plan and execute">'
        '<Work name="activate controllers"/>'
        '<Script name="plan" code="trajectory := target .. \'/planned\'"/>'
        '<Work name="validate trajectory"/>'
        '<Fallback name="execute"><Work name="execute trajectory"/><AlwaysFailure name="stop"/></Fallback>'
        "</Sequence></BehaviorTree>"
    )
    move_to_waypoint = (
        '<BehaviorTree ID="Move to Waypoint"><Sequence name="move to waypoint">'
        '<Script name="look up the waypoint" code="target_joint_state := waypoint_name"/>'
        '<SubTree ID="Move to Joint State" name="plan and execute" target="{target_joint_state}"'
        ' joint_group_name="{joint_group_name}"/>'
        "</Sequence></BehaviorTree>"
    )
    gripper = (
        '<BehaviorTree ID="Open Gripper"><Work name="open gripper"/></BehaviorTree>'
        '<BehaviorTree ID="Close Gripper"><Work name="close gripper"/></BehaviorTree>'
    )
    carry = (
        '<BehaviorTree ID="Pick and Place Between Waypoints"><Sequence name="carry">'
        '<SubTree ID="Move to Waypoint" name="down to the object" waypoint_name="{from}"'
        ' joint_group_name="{group}"/>'
        '<SubTree ID="Close Gripper" name="grasp"/>'
        '<SubTree ID="Move to Waypoint" name="lift" waypoint_name="{mid}" joint_group_name="{group}"/>'
        '<SubTree ID="Move to Waypoint" name="down to the target" waypoint_name="{to}"'
        ' joint_group_name="{group}"/>'
        '<SubTree ID="Open Gripper" name="release"/>'
        '<SubTree ID="Move to Waypoint" name="back up" waypoint_name="{mid}" joint_group_name="{group}"/>'
        '<Script name="count" code="cycles += 1"/>'
        "</Sequence></BehaviorTree>"
    )
    main = (
        '<BehaviorTree ID="Main"><Sequence name="pick and place">'
        "<Script name=\"setup\" code=\"mid := 'mid'; pick := 'pick'; place := 'place'; group := 'arm'\"/>"
        '<SubTree ID="Move to Waypoint" name="start above the table" waypoint_name="{mid}"'
        ' joint_group_name="{group}"/>'
        '<SubTree ID="Open Gripper" name="open"/>'
        '<KeepRunningUntilFailure name="until cancelled"><Sequence name="one cycle">'
        '<SubTree ID="Pick and Place Between Waypoints" name="table to tray" from="{pick}" to="{place}"'
        ' mid="{mid}" group="{group}" cycles="{cycles}"/>'
        '<SubTree ID="Pick and Place Between Waypoints" name="tray to table" from="{place}" to="{pick}"'
        ' mid="{mid}" group="{group}" cycles="{cycles}"/>'
        "</Sequence></KeepRunningUntilFailure></Sequence></BehaviorTree>"
    )
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Main">'
        f"{main}{carry}{move_to_waypoint}{move_to_joint_state}{gripper}</root>"
    )


STRUCTURES = {"sequence": sequence_xml, "mixed": mixed_xml, "pick_place": pick_place_xml}


# -- engines ----------------------------------------------------------------------------------------


def kinema_factory() -> Any:
    from kinema.bt import BehaviorTreeFactory, NodeStatus

    factory = BehaviorTreeFactory()
    factory.register_simple_action("Work", lambda node: NodeStatus.SUCCESS)
    return factory


def kinema_tree(xml: str, factory: Any = None) -> Any:
    """Build ``xml`` with ``factory``, or with a new factory (registering the built-ins) if None."""
    from kinema.bt import Blackboard

    factory = factory if factory is not None else kinema_factory()
    bb = Blackboard.create()
    bb.set("counter", 0)
    bb.set("cycles", 0)
    return factory.create_tree_from_text(xml, bb)


_KEEP_ALIVE: list[Any] = []


def btcpp_factory() -> Any:
    import behaviortreepy as bt

    factory = bt.BehaviorTreeFactory()
    success = bt.NodeStatus.SUCCESS
    factory.register_simple_action("Work", lambda node: success)
    return factory


def btcpp_tree(xml: str, factory: Any = None) -> Any:
    """Build ``xml`` with ``factory``, or with a new factory if None."""
    import behaviortreepy as bt

    factory = factory if factory is not None else btcpp_factory()
    bb = bt.Blackboard.create()
    bb.set_int("counter", 0)
    bb.set_int("cycles", 0)
    tree = factory.create_tree_from_text(xml, bb)
    _KEEP_ALIVE.append((factory, bb))  # BT.CPP 4.8 trees must not outlive their factory (#1046)
    return tree


class BtcppRecorded:
    """A BT.CPP tree with its ``FileLogger2`` attached, writing to a temporary folder."""

    def __init__(self, xml: str) -> None:
        import os
        import tempfile

        import behaviortreepy as bt

        self._folder = tempfile.TemporaryDirectory(prefix="kinema-bench-btcpp-")
        self.tree = btcpp_tree(xml)
        self.logger = bt.FileLogger(self.tree, os.path.join(self._folder.name, "run.btlog"))
        self.tick = self.tree.tick_once


class _SerializingPublisher:
    """A publisher that does the agent's work up to the network: the message to CDR bytes (the node
    status codes come already serialised)."""

    def __init__(self, type_name: str) -> None:
        from kinema.transport.messages import _registry

        self.type_name = type_name
        self.registry = _registry(None)
        self.sent = 0

    def publish(self, message: Any) -> None:
        self.sent += len(self.registry.serialize(message, self.type_name))

    def publish_raw(self, payload: bytes) -> None:
        self.sent += len(payload)


class ObjectiveObservers:
    """What the runtime attaches to a running tree, all of it on the tick thread: the objective
    server's NodeStatusRecorder (the transition log, read after every tick), the agent's streams
    (node status and node table messages built and serialised to CDR; the blackboard snapshot at
    10 Hz, rendered and serialised) and the run recording (``.btlog`` and blackboard file, written
    to a temporary folder). Only the network and Groot2's sockets are left out."""

    def __init__(self, tree: Any) -> None:
        import tempfile
        from types import SimpleNamespace

        from kinema.runtime.agent import _Streams
        from kinema.runtime.node_status import NodeStatusRecorder
        from kinema.runtime.objective_server import blackboard_entries
        from kinema.runtime.recordings import RunRecorder

        self.tree = tree
        self.recorder = NodeStatusRecorder()
        self._folder = tempfile.TemporaryDirectory(prefix="kinema-bench-")
        node = SimpleNamespace(
            create_publisher=lambda type_name, _topic, **_: _SerializingPublisher(type_name)
        )
        self.streams = _Streams(node, None, SimpleNamespace())  # type: ignore[arg-type]
        # Every transition is written, as FileLogger2 writes them (no size cap).
        unlimited = 1 << 40
        self.recording = RunRecorder(self._folder.name, max_file_bytes=unlimited, max_total_bytes=unlimited)
        self.recording.on_tree_loaded("bench", tree)
        self._last = 0.0
        self._entries = blackboard_entries
        self.recorder.attach(tree)

    def tick(self) -> None:
        self.tree.tick_once()
        changes = self.recorder.take()
        if changes is not None:
            self.streams.on_node_status("bench", changes)
            self.recording.on_node_status("bench", changes)
        now = time.monotonic()
        if now - self._last >= 0.1:
            self._last = now
            entries = self._entries(self.tree)
            self.streams.on_blackboard("bench", entries)
            self.recording.on_blackboard("bench", entries)


# -- py_trees equivalents ---------------------------------------------------------------------------


def py_trees_sequence(n: int = N_LEAVES) -> Any:
    import py_trees

    children = [py_trees.behaviours.Success(name=f"s{i}") for i in range(n)]
    return py_trees.composites.Sequence(name="root", memory=True, children=children)


def py_trees_mixed(groups: int = N_GROUPS) -> Any:
    """py_trees version of :func:`mixed_xml` (same node count and control flow)."""
    import py_trees

    class Increment(py_trees.behaviour.Behaviour):
        def __init__(self, name: str) -> None:
            super().__init__(name)
            self.bb = self.attach_blackboard_client()
            self.bb.register_key("counter", access=py_trees.common.Access.WRITE)

        def update(self) -> Any:
            self.bb.counter += 1
            return py_trees.common.Status.SUCCESS

    py_trees.blackboard.Blackboard.clear()
    writer = py_trees.blackboard.Client(name="setup")
    writer.register_key("counter", access=py_trees.common.Access.WRITE)
    writer.counter = 0
    groups_nodes = []
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
        groups_nodes.append(
            py_trees.composites.Sequence(
                name=f"g{g}",
                memory=False,
                children=[check, inverted, fallback, Increment(f"inc{g}"), subtree],
            )
        )
    return py_trees.composites.Sequence(name="root", memory=True, children=groups_nodes)


# -- measuring --------------------------------------------------------------------------------------


def rate(tick: Callable[[], object], seconds: float, rounds: int) -> float:
    """Median ticks per CPU second over ``rounds`` rounds of ``seconds / rounds`` each."""
    rates = []
    for _ in range(rounds):
        count = 0
        start = time.process_time()
        deadline = start + seconds / rounds
        while True:
            for _ in range(5):
                tick()
            count += 5
            now = time.process_time()
            if now >= deadline:
                break
        rates.append(count / (now - start))
    return statistics.median(rates)


def build_ms(build: Callable[[], object], rounds: int) -> float:
    """Median CPU milliseconds of ``build()`` over ``max(rounds, 5) * 2`` runs."""
    times = []
    for _ in range(max(rounds, 5) * 2):
        start = time.process_time()
        build()
        times.append((time.process_time() - start) * 1000.0)
    return statistics.median(times)


def _btcpp_available() -> bool:
    try:
        import behaviortreepy  # noqa: F401
    except ImportError:
        print("behaviortreepy is not installed (pip install -e '.[test]'): BT.CPP columns are empty")
        return False
    return True


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=3.0, help="CPU seconds per engine and structure")
    parser.add_argument("--rounds", type=int, default=5, help="rounds per measurement (median)")
    parser.add_argument("--profile", choices=sorted(STRUCTURES), help="profile Kinema ticking STRUCTURE")
    parser.add_argument(
        "--smoke", action="store_true", help="tiny timings of each structure (the test suite)"
    )
    args = parser.parse_args()
    if args.smoke:
        args.seconds, args.rounds = 0.02, 1

    if args.profile:
        tree = kinema_tree(STRUCTURES[args.profile]())
        profiler = cProfile.Profile()
        profiler.enable()
        for _ in range(300):
            tree.tick_once()
        profiler.disable()
        pstats.Stats(profiler).sort_stats("tottime").print_stats(25)
        return

    have_btcpp = _btcpp_available()
    py_trees_builders = {"sequence": py_trees_sequence, "mixed": py_trees_mixed}
    print(f"ticks per CPU second, median of {args.rounds} rounds; ratio = BT.CPP rate / Kinema rate")
    print(
        "plain: nothing attached; recorded: Kinema with the runtime's observers, BT.CPP with its FileLogger2;"
        " cost: recorded against plain"
    )
    header = f"{'structure':<12} {'nodes':>6} {'BT.CPP':>9} {'Kinema':>9} {'ratio':>6} "
    header += f"{'BT.CPP rec':>11} {'cost':>6} {'Kinema rec':>11} {'cost':>6} {'ratio':>6} {'py_trees':>9}"
    print(header)
    nan = float("nan")
    for name, make_xml in STRUCTURES.items():
        xml = make_xml()
        tree = kinema_tree(xml)
        kinema = rate(tree.tick_once, args.seconds, args.rounds)
        observers = ObjectiveObservers(kinema_tree(xml))
        observed = rate(observers.tick, args.seconds, args.rounds)
        btcpp = btcpp_recorded = nan
        if have_btcpp:
            btcpp = rate(btcpp_tree(xml).tick_once, args.seconds, args.rounds)
            recorded = BtcppRecorded(xml)  # the logger lives as long as this object
            btcpp_recorded = rate(recorded.tick, args.seconds, args.rounds)
        pt = nan
        if name in py_trees_builders:
            pt = rate(py_trees_builders[name]().tick_once, args.seconds, args.rounds)
        print(
            f"{name:<12} {len(tree):>6} {btcpp:>9.0f} {kinema:>9.0f} {btcpp / kinema:>5.2f}x "
            f"{btcpp_recorded:>11.0f} {btcpp / btcpp_recorded - 1.0:>+6.0%} "
            f"{observed:>11.0f} {kinema / observed - 1.0:>+6.0%} {btcpp_recorded / observed:>5.2f}x "
            f"{pt:>9.0f}"
        )
    print("\nbuild from XML, CPU ms (median); ratio = Kinema / BT.CPP")
    print("  new factory each time (built-ins registered, the text parsed, verified and compiled):")
    for name in ("sequence", "mixed", "pick_place"):
        xml = STRUCTURES[name]()
        kinema_ms = build_ms(lambda xml=xml: kinema_tree(xml), args.rounds)
        btcpp_ms = build_ms(lambda xml=xml: btcpp_tree(xml), args.rounds) if have_btcpp else float("nan")
        ratio = kinema_ms / btcpp_ms
        print(f"  {name:<12} BT.CPP {btcpp_ms:7.2f} ms   Kinema {kinema_ms:7.2f} ms   {ratio:5.2f}x")
    print("  the same factory again (a hot reload of an unchanged file, /do_objective with the same XML):")
    for name in ("sequence", "mixed", "pick_place"):
        xml = STRUCTURES[name]()
        kf = kinema_factory()
        kinema_ms = build_ms(lambda xml=xml, kf=kf: kinema_tree(xml, kf), args.rounds)
        btcpp_ms = float("nan")
        if have_btcpp:
            bf = btcpp_factory()
            btcpp_ms = build_ms(lambda xml=xml, bf=bf: btcpp_tree(xml, bf), args.rounds)
        ratio = kinema_ms / btcpp_ms
        print(f"  {name:<12} BT.CPP {btcpp_ms:7.2f} ms   Kinema {kinema_ms:7.2f} ms   {ratio:5.2f}x")


if __name__ == "__main__":
    main()
