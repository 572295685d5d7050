"""Run the same BT.CPP v4 XML in Kinema and in the real BehaviorTree.CPP (``behaviortreepy``, 4.8.2).

Used by the differential test. Both engines get the same scripted leaves, keyed by the node's
(unique) instance name:

* ``Act``   - a simple action returning its script of SUCCESS/FAILURE in turn (cycling);
* ``Cond``  - a simple condition, same;
* ``Async`` - a stateful action whose ``on_start``/``on_running`` calls return its script in turn,
  cycling, so it may be RUNNING for a few ticks; halts are logged.

One run ticks the tree ``ticks`` times with ``tickExactlyOnce`` (optionally halting it before a given
tick) and records, per tick: the root status or that an exception escaped, every status transition
``(name, prev, new)`` in order, and the leaves' calls. At the end it records the root blackboard
(values printed the way ``BT::Any`` converts them to ``std::string``).

BT.CPP's transitions are read from its ``StdCoutLogger`` (the bindings expose no observer), by
redirecting file descriptor 1 around each tick.
"""

from __future__ import annotations

import ctypes
import os
import re
import tempfile
from dataclasses import dataclass, field
from typing import Any

from kinema.bt import BehaviorTreeFactory, Blackboard, NodeStatus, StatefulActionNode, TreeNode

STATUS_NAMES = ("IDLE", "RUNNING", "SUCCESS", "FAILURE", "SKIPPED")


@dataclass
class Leaves:
    """Scripts of the scripted leaves: instance name -> statuses (names from STATUS_NAMES)."""

    scripts: dict[str, list[str]] = field(default_factory=dict)


@dataclass
class TickRecord:
    """What one tick did."""

    result: str  # a status name, or "EXCEPTION"
    transitions: list[tuple[str, str, str]]
    calls: list[str]

    def describe(self) -> str:
        lines = [f"  result {self.result}"]
        lines += [f"    {n}: {a} -> {b}" for n, a, b in self.transitions]
        lines += [f"    call {c}" for c in self.calls]
        return "\n".join(lines)


@dataclass
class RunRecord:
    """The outcome of creating and ticking one tree."""

    build_error: str | None = None
    ticks: list[TickRecord] = field(default_factory=list)
    blackboard: dict[str, str] = field(default_factory=dict)
    errors: list[str] = field(default_factory=list)


def _cpp_text(value: Any) -> str:
    """A Kinema blackboard value as BT.CPP's ``Any`` prints it (``std::to_string`` for doubles)."""
    if value is None:
        return "<empty>"
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, float):
        return f"{value:f}"
    return str(value)


class _Calls:
    def __init__(self, leaves: Leaves) -> None:
        self.leaves = leaves
        self.count: dict[str, int] = {}
        self.log: list[str] = []

    def next(self, name: str, what: str) -> str:
        script = self.leaves.scripts[name]
        k = self.count.get(name, 0)
        self.count[name] = k + 1
        status = script[k % len(script)]
        self.log.append(f"{what} {name} -> {status}")
        return status


def _halt(halt_tree: Any, record: RunRecord, i: int) -> str:
    try:
        halt_tree()
    except Exception as error:
        record.errors.append(f"halt before tick {i}: {type(error).__name__}: {error}")
        return "HALT-EXCEPTION"
    return "HALT"


# -- Kinema ----------------------------------------------------------------------------------------


def run_kinema(xml: str, leaves: Leaves, ticks: int, halt_before: int | None, seed_bb: dict) -> RunRecord:
    """Build ``xml`` with Kinema and tick it."""
    calls = _Calls(leaves)
    factory = BehaviorTreeFactory()

    def simple(node: TreeNode) -> NodeStatus:
        return NodeStatus[calls.next(node.name, "tick")]

    factory.register_simple_action("Act", simple)
    factory.register_simple_condition("Cond", simple)

    class Async(StatefulActionNode):
        def on_start(self) -> NodeStatus:
            return NodeStatus[calls.next(self.name, "start")]

        def on_running(self) -> NodeStatus:
            return NodeStatus[calls.next(self.name, "running")]

        def on_halted(self) -> None:
            calls.log.append(f"halted {self.name}")

    factory.register_node_type(Async, "Async")
    record = RunRecord()
    bb = Blackboard.create()
    for key, value in seed_bb.items():
        bb.set(key, value)
    try:
        tree = factory.create_tree_from_text(xml, bb)
    except Exception as error:
        record.build_error = f"{type(error).__name__}: {error}"
        return record
    transitions: list[tuple[str, str, str]] = []
    tree.add_status_observer(lambda _t, node, prev, new: transitions.append((node.name, prev.name, new.name)))
    for i in range(ticks):
        transitions.clear()
        calls.log = []
        if halt_before == i:
            result = _halt(tree.halt_tree, record, i)
            record.ticks.append(TickRecord(result, list(transitions), calls.log))
            transitions.clear()
            calls.log = []
        try:
            result = tree.tick_exactly_once().name
        except Exception as error:
            result = "EXCEPTION"
            record.errors.append(f"tick {i}: {type(error).__name__}: {error}")
        record.ticks.append(TickRecord(result, list(transitions), calls.log))
    root = tree.root_blackboard
    record.blackboard = {key: _cpp_text(root.get_entry(key).value) for key in root.keys()}
    return record


# -- BT.CPP ----------------------------------------------------------------------------------------

_LOG_LINE = re.compile(r"^\[[0-9.]+\]: (.*?) +(?:\x1b\[\d+m)?(\w+)(?:\x1b\[0m)? -> (?:\x1b\[\d+m)?(\w+)")


class _StdoutCapture:
    """Collects what C++ code prints to file descriptor 1 while active."""

    def __init__(self) -> None:
        self._libc = ctypes.CDLL(None)
        self._file = tempfile.TemporaryFile()
        self._saved = -1

    def __enter__(self) -> _StdoutCapture:
        self._libc.fflush(None)
        self._saved = os.dup(1)
        self._file.seek(0)
        self._file.truncate()
        os.dup2(self._file.fileno(), 1)
        return self

    def __exit__(self, *exc: object) -> None:
        self._libc.fflush(None)
        os.dup2(self._saved, 1)
        os.close(self._saved)

    def transitions(self) -> list[tuple[str, str, str]]:
        self._file.seek(0)
        out = []
        for line in self._file.read().decode(errors="replace").splitlines():
            match = _LOG_LINE.match(line)
            if match:
                out.append((match.group(1), match.group(2), match.group(3)))
        return out

    def close(self) -> None:
        self._file.close()


def _cpp_blackboard_text(bb: Any, key: str) -> str:
    try:
        return bb.get_string(key)
    except Exception:
        return "<empty>"


def run_btcpp(xml: str, leaves: Leaves, ticks: int, halt_before: int | None, seed_bb: dict) -> RunRecord:
    """Build ``xml`` with BT.CPP (behaviortreepy) and tick it."""
    import behaviortreepy as bt

    calls = _Calls(leaves)
    factory = bt.BehaviorTreeFactory()

    def simple(node: Any) -> Any:
        return getattr(bt.NodeStatus, calls.next(node.name(), "tick"))

    def on_start(node: Any) -> Any:
        return getattr(bt.NodeStatus, calls.next(node.name(), "start"))

    def on_running(node: Any) -> Any:
        return getattr(bt.NodeStatus, calls.next(node.name(), "running"))

    def on_halted(node: Any) -> None:
        calls.log.append(f"halted {node.name()}")

    factory.register_simple_action("Act", simple)
    factory.register_simple_condition("Cond", simple)
    factory.register_simple_stateful_action("Async", on_start, on_running, on_halted)
    record = RunRecord()
    bb = bt.Blackboard.create()
    for key, value in seed_bb.items():
        if isinstance(value, bool):
            bb.set_bool(key, value)
        elif isinstance(value, int):
            bb.set_int(key, value)
        elif isinstance(value, float):
            bb.set_double(key, value)
        else:
            bb.set_string(key, value)
    try:
        tree = factory.create_tree_from_text(xml, bb)
    except Exception as error:
        record.build_error = f"{type(error).__name__}: {error}"
        return record
    logger = bt.StdCoutLogger(tree)
    capture = _StdoutCapture()
    try:
        for i in range(ticks):
            calls.log = []
            if halt_before == i:
                with capture:
                    result = _halt(tree.halt_tree, record, i)
                record.ticks.append(TickRecord(result, capture.transitions(), calls.log))
                calls.log = []
            with capture:
                try:
                    result = tree.tick_exactly_once().name
                except Exception as error:
                    result = "EXCEPTION"
                    record.errors.append(f"tick {i}: {type(error).__name__}: {error}")
            record.ticks.append(TickRecord(result, capture.transitions(), calls.log))
        root = tree.root_blackboard()
        record.blackboard = {key: _cpp_blackboard_text(root, key) for key in root.get_keys()}
    finally:
        calls.log = []  # the Tree destructor halts the tree: not part of any tick
        with capture:
            del logger
            del tree
        capture.close()
    return record


def compare(kinema: RunRecord, btcpp: RunRecord) -> str | None:
    """None when both runs agree, else a readable account of the first difference."""
    if (kinema.build_error is None) != (btcpp.build_error is None):
        return f"tree creation differs:\n  kinema: {kinema.build_error}\n  BT.CPP: {btcpp.build_error}"
    if kinema.build_error is not None:
        return None
    for i, (k, c) in enumerate(zip(kinema.ticks, btcpp.ticks, strict=True)):
        if k != c:
            return (
                f"tick {i} differs\n kinema:\n{k.describe()}\n BT.CPP:\n{c.describe()}\n"
                f" kinema errors: {kinema.errors}\n BT.CPP errors: {btcpp.errors}"
            )
    if kinema.blackboard != btcpp.blackboard:
        return f"final blackboard differs\n  kinema: {kinema.blackboard}\n  BT.CPP: {btcpp.blackboard}"
    return None
