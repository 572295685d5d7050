"""Decorators, including the time-based ones on a manual clock (no wall-clock waiting)."""

from __future__ import annotations

import pytest

from kinema.bt import BehaviorTreeFactory, BTError, ManualClock, NodeStatus

S, F, R, K = NodeStatus.SUCCESS, NodeStatus.FAILURE, NodeStatus.RUNNING, NodeStatus.SKIPPED


@pytest.mark.parametrize(
    ("decorator", "child", "expected"),
    [
        ("Inverter", S, F),
        ("Inverter", F, S),
        ("ForceSuccess", F, S),
        ("ForceFailure", S, F),
        ("KeepRunningUntilFailure", S, R),
        ("KeepRunningUntilFailure", F, F),
    ],
)
def test_simple_decorators(bench, decorator: str, child: NodeStatus, expected: NodeStatus) -> None:
    bench.action("Child", child)
    assert bench.tree(f"<{decorator}><Child/></{decorator}>").tick_once() is expected


@pytest.mark.parametrize("decorator", ["Inverter", "ForceSuccess", "ForceFailure"])
def test_skipped_passes_through(bench, decorator: str) -> None:
    tree = bench.tree(f'<Sequence><{decorator}><AlwaysSuccess _skipIf="true"/></{decorator}></Sequence>')
    assert tree.tick_once() is K


def test_keep_running_until_failure_turns_skipped_into_running(bench) -> None:
    tree = bench.tree('<KeepRunningUntilFailure><AlwaysSuccess _skipIf="true"/></KeepRunningUntilFailure>')
    assert tree.tick_once() is R


def test_repeat_counts_successes_and_yields_between_cycles(bench) -> None:
    bench.action("A")
    tree = bench.tree('<Repeat num_cycles="3"><A/></Repeat>')
    assert tree.tick_exactly_once() is R
    assert bench.ticks["A"] == 1
    assert tree.tick_once() is S  # follows the wake-ups through the remaining cycles
    assert bench.ticks["A"] == 3


@pytest.mark.parametrize(("cycles", "ticks"), [("0", 0), ("2.7", 2), ("1", 1)])
def test_repeat_cycles_parse_like_cpp(bench, cycles: str, ticks: int) -> None:
    bench.action("A")
    assert bench.tree(f'<Repeat num_cycles="{cycles}"><A/></Repeat>').tick_once() is S
    assert bench.ticks["A"] == ticks


def test_repeat_stops_on_failure(bench) -> None:
    bench.action("A", S, F)
    assert bench.tree('<Repeat num_cycles="5"><A/></Repeat>').tick_once() is F
    assert bench.ticks["A"] == 2


def test_retry_until_successful(bench) -> None:
    bench.action("Flaky", F, F, S)
    tree = bench.tree('<RetryUntilSuccessful num_attempts="5"><Flaky/></RetryUntilSuccessful>')
    assert tree.tick_exactly_once() is R
    assert tree.tick_once() is S
    assert bench.ticks["Flaky"] == 3
    bench.action("Never", F)
    assert (
        bench.tree('<RetryUntilSuccessful num_attempts="2"><Never/></RetryUntilSuccessful>').tick_once() is F
    )
    assert bench.ticks["Never"] == 2


def test_bad_literal_port_is_rejected_when_building(bench) -> None:
    with pytest.raises(BTError, match="can not be converted to int"):
        bench.tree('<Repeat num_cycles="abc"><AlwaysSuccess/></Repeat>')


def test_run_once(bench) -> None:
    bench.action("A", F)
    tree = bench.tree('<Sequence><RunOnce then_skip="false"><A/></RunOnce></Sequence>')
    assert [tree.tick_once() for _ in range(3)] == [F, F, F]
    assert bench.ticks["A"] == 1
    bench.action("B")
    skipping = bench.tree("<RunOnce><B/></RunOnce>")
    assert [skipping.tick_once() for _ in range(2)] == [S, K]
    skipping.halt_tree()
    assert skipping.tick_once() is K  # the flag survives halt


def test_precondition_else_status_and_single_check(bench) -> None:
    bench.stateful("Work", running_ticks=1)
    tree = bench.tree('<Precondition if="go == 1" else="SKIPPED"><Work/></Precondition>')
    bb = tree.root_blackboard
    bb.set("go", 0)
    assert tree.tick_once() is K
    bb.set("go", 1)
    assert tree.tick_once() is R
    bb.set("go", 0)
    assert tree.tick_once() is S  # not re-checked while the child runs


def test_timeout_halts_a_slow_child_on_the_tree_clock() -> None:
    clock = ManualClock()
    factory = BehaviorTreeFactory(clock=clock)
    halted = []

    from kinema.bt import StatefulActionNode

    class Slow(StatefulActionNode):
        def on_start(self) -> NodeStatus:
            return R

        def on_running(self) -> NodeStatus:
            return R

        def on_halted(self) -> None:
            halted.append(clock.now())

    factory.register_node_type(Slow, "Slow")
    tree = factory.create_tree_from_text(
        '<root BTCPP_format="4"><BehaviorTree ID="M">'
        '<Timeout msec="500"><Slow/></Timeout></BehaviorTree></root>'
    )
    assert tree.tick_once() is R
    clock.advance(0.4)
    assert tree.tick_once() is R
    clock.advance(0.2)
    assert tree.wake_up.consume()  # the timer woke the tree up
    assert tree.tick_once() is F
    assert halted == [pytest.approx(0.6)]


def test_timeout_passes_through_a_fast_child() -> None:
    clock = ManualClock()
    factory = BehaviorTreeFactory(clock=clock)
    tree = factory.create_tree_from_text(
        '<root BTCPP_format="4"><BehaviorTree ID="M"><Timeout msec="500"><AlwaysSuccess/></Timeout>'
        "</BehaviorTree></root>"
    )
    assert tree.tick_once() is S
    clock.advance(1.0)
    assert tree.tick_once() is S


def test_delay_and_sleep_follow_the_tree_clock() -> None:
    clock = ManualClock()
    factory = BehaviorTreeFactory(clock=clock)
    tree = factory.create_tree_from_text(
        '<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence>'
        '<Delay delay_msec="100"><AlwaysSuccess/></Delay><Sleep msec="200"/>'
        "</Sequence></BehaviorTree></root>"
    )
    assert tree.tick_once() is R
    clock.advance(0.099)
    assert tree.tick_once() is R
    clock.advance(0.001)
    assert tree.tick_once() is R  # the delay is over, Sleep started
    clock.advance(0.199)
    assert tree.tick_once() is R
    clock.advance(0.001)
    assert tree.tick_once() is S


def test_sleep_zero_succeeds_immediately(bench) -> None:
    assert bench.tree('<Sleep msec="0"/>').tick_once() is S


def test_halting_a_sleep_cancels_its_timer() -> None:
    clock = ManualClock()
    factory = BehaviorTreeFactory(clock=clock)
    tree = factory.create_tree_from_text(
        '<root BTCPP_format="4"><BehaviorTree ID="M"><Sleep msec="100"/></BehaviorTree></root>'
    )
    assert tree.tick_once() is R
    tree.halt_tree()
    clock.advance(1.0)
    assert not tree.wake_up.consume()


@pytest.mark.parametrize(
    ("node", "queue", "statuses", "values"),
    [
        ("LoopInt", "1;2;3", [R, R, R, S], [1, 2, 3]),
        ("LoopDouble", "0.5;1.5", [R, R, S], [0.5, 1.5]),
        ("LoopString", "a;b", [R, R, S], ["a", "b"]),
        ("LoopBool", "true;0", [R, R, S], [True, False]),
    ],
)
def test_loop_nodes_pop_one_value_per_tick(bench, node, queue, statuses, values) -> None:
    seen = []

    def record(n):
        seen.append(n.get_input("v"))
        return S

    from kinema.bt import input_port

    bench.factory.register_simple_action("Record", record, [input_port("v")])
    tree = bench.tree(f'<{node} queue="{queue}" value="{{x}}"><Record v="{{x}}"/></{node}>')
    assert [tree.tick_exactly_once() for _ in statuses] == statuses
    assert seen == values


def test_loop_reads_a_list_from_the_blackboard_and_if_empty(bench) -> None:
    bench.action("A")
    tree = bench.tree('<LoopInt queue="{items}" value="{x}"><A/></LoopInt>')
    tree.root_blackboard.set("items", [4, 5])
    assert tree.tick_while_running(0) is S
    assert bench.ticks["A"] == 2
    empty = bench.tree('<LoopInt queue="" if_empty="FAILURE" value="{x}"><A/></LoopInt>')
    assert empty.tick_once() is F


def test_skip_unless_updated_and_wait_value_update(bench) -> None:
    bench.action("A")
    tree = bench.tree('<Sequence><SkipUnlessUpdated entry="k"><A/></SkipUnlessUpdated></Sequence>')
    assert tree.tick_once() is K  # no entry yet
    tree.root_blackboard.set("k", 1)
    assert tree.tick_once() is S
    assert tree.tick_once() is K  # not updated since
    waiting = bench.tree('<WaitValueUpdate entry="{k2}"><A/></WaitValueUpdate>')
    assert waiting.tick_once() is R
    waiting.root_blackboard.set("k2", "x")
    assert waiting.tick_once() is S


def test_was_entry_updated(bench) -> None:
    tree = bench.tree('<WasEntryUpdated entry="k"/>')
    assert tree.tick_once() is F
    tree.root_blackboard.set("k", 1)
    assert [tree.tick_once(), tree.tick_once()] == [S, F]
