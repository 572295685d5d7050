"""After a failed run the tree shows the statuses BehaviorTree.CPP leaves, checked against behaviortreepy.

Both engines run the same XML with the same scripted leaves (``tests/unit/bt/btcpp_oracle.py``); Kinema's
transitions are what the runtime streams, fed to the app as node statuses, then the run's failure
message. A node shows the last status BT.CPP gave it before resetting it to IDLE; no node BT.CPP never
halted shows HALTED (a parent Sequence did, after its child failed).
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from tui_pilot_harness import drive, settle

pytest.importorskip("behaviortreepy", reason="behaviortreepy (real BT.CPP) is not installed")
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "unit" / "bt"))

from btcpp_oracle import Leaves, RunRecord, run_btcpp, run_kinema

from kinema.tui.connection import (
    Heartbeat,
    LogEntry,
    LogLevel,
    NodeStatus,
    NodeStatusBatch,
    NodeStatusUpdate,
    ObjectiveSummary,
)
from kinema.tui.fake_connection import FakeConnection
from kinema.tui.tree_outline import build_outline
from kinema.tui.widgets.behavior_tree_view import BehaviorTreeView


def doc(body: str) -> str:
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Main">'
        f'<BehaviorTree ID="Main">{body}</BehaviorTree></root>'
    )


def last_results(record: RunRecord) -> dict[str, str]:
    """Each node's last status other than IDLE, from BT.CPP's transitions (parents reset to IDLE)."""
    shown: dict[str, str] = {}
    for tick in record.ticks:
        for name, _, new in tick.transitions:
            if new != "IDLE":
                shown[name] = new
    return shown


def shown_after(xml: str, kinema: RunRecord, failure: str) -> dict[str, str]:
    """What the app's tree shows for each node after Kinema's transitions and the failure message."""
    outline = build_outline(xml, "Main")
    by_name = {node.name: node for node in outline.nodes()}
    fake = FakeConnection(objectives=[ObjectiveSummary("Main")], xml={"Main": xml})
    shown: dict[str, str] = {}

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        fake.emit(Heartbeat(1.0, "Main", "Running"))
        for tick in kinema.ticks:
            updates = tuple(
                NodeStatusUpdate(
                    by_name[name].uid,
                    by_name[name].path,
                    by_name[name].type_id,
                    name,
                    NodeStatus[new],
                    NodeStatus[old],
                )
                for name, old, new in tick.transitions
            )
            fake.emit(NodeStatusBatch("Main", updates))
        fake.emit(Heartbeat(2.0, "Main", "Failure"))
        fake.emit(LogEntry(f"objective 'Main' failed (FAILURE): {failure}", LogLevel.ERROR, 1.0))
        await settle(pilot)
        view = app.screen.query_one(BehaviorTreeView)
        shown.update({name: view.shown_as(node.path) for name, node in by_name.items()})

    drive(fake, scenario)
    return shown


def test_a_child_that_fails_fails_its_sequence_as_in_btcpp() -> None:
    xml = doc('<Sequence name="seq"><Act name="ok"/><Async name="slow"/></Sequence>')
    leaves = Leaves({"ok": ["SUCCESS"], "slow": ["RUNNING", "FAILURE"]})
    kinema, btcpp = (run(xml, leaves, 2, None, {}) for run in (run_kinema, run_btcpp))
    assert [t.result for t in btcpp.ticks] == ["RUNNING", "FAILURE"]
    expected = last_results(btcpp)
    assert expected == {"seq": "FAILURE", "ok": "SUCCESS", "slow": "FAILURE"}
    shown = shown_after(xml, kinema, "objective 'Main' failed: node 'slow' [Async] returned FAILURE")
    assert shown == expected


def test_an_exception_fails_the_nodes_it_escaped_through_and_halts_none_of_them() -> None:
    # Script n3 reads a key nobody wrote: it throws. BT.CPP leaves the Sequence RUNNING (it never halts
    # it: the runtime does, to stop the failed tree); the Sequence failed with its child, not HALTED.
    xml = doc('<Sequence name="seq"><Act name="ok"/><Script name="bad" code="c += 1"/></Sequence>')
    leaves = Leaves({"ok": ["SUCCESS"]})
    kinema, btcpp = (run(xml, leaves, 1, None, {}) for run in (run_kinema, run_btcpp))
    assert [t.result for t in btcpp.ticks] == ["EXCEPTION"]
    transitions = [t for tick in btcpp.ticks for t in tick.transitions]
    assert ("seq", "RUNNING", "IDLE") not in transitions and last_results(btcpp)["seq"] == "RUNNING"
    shown = shown_after(xml, kinema, "<objective>:1: Exception in node 'bad' [Script]: no entry c")
    assert shown == {"seq": "FAILURE", "ok": "SUCCESS", "bad": "FAILURE"}
