"""Control nodes: statuses, memory, halting and wake-up yields, as BT.CPP 4.10 does them."""

from __future__ import annotations

import pytest

from kinema.bt import BTError, NodeStatus

S, F, R, K = NodeStatus.SUCCESS, NodeStatus.FAILURE, NodeStatus.RUNNING, NodeStatus.SKIPPED


@pytest.mark.parametrize(
    ("control", "results", "expected", "ticked"),
    [
        ("Sequence", (S, S, S), S, (1, 1, 1)),
        ("Sequence", (S, F, S), F, (1, 1, 0)),
        ("Fallback", (F, S, F), S, (1, 1, 0)),
        ("Fallback", (F, F, F), F, (1, 1, 1)),
        ("ReactiveSequence", (S, F, S), F, (1, 1, 0)),
        ("ReactiveFallback", (F, F, S), S, (1, 1, 1)),
        ("SequenceWithMemory", (S, S, S), S, (1, 1, 1)),
        ("AsyncSequence", (S, S, S), S, (1, 1, 1)),
        ("AsyncFallback", (F, F, F), F, (1, 1, 1)),
    ],
)
def test_control_results(bench, control: str, results: tuple, expected: NodeStatus, ticked: tuple) -> None:
    for name, result in zip("ABC", results, strict=True):
        bench.action(name, result)
    tree = bench.tree(f"<{control}><A/><B/><C/></{control}>")
    assert tree.tick_while_running() is expected
    assert tuple(bench.ticks[n] for n in "ABC") == ticked


def test_sequence_keeps_its_place_while_a_child_runs(bench) -> None:
    bench.action("A")
    bench.stateful("Work", running_ticks=2)
    tree = bench.tree("<Sequence><A/><Work/></Sequence>")
    assert [tree.tick_once() for _ in range(3)] == [R, R, S]
    assert bench.ticks["A"] == 1  # not re-evaluated while Work runs


def test_reactive_sequence_re_evaluates_conditions_and_halts_the_runner(bench) -> None:
    bench.condition("Check", S, S, F)
    bench.stateful("Work", running_ticks=-1)
    tree = bench.tree("<ReactiveSequence><Check/><Work/></ReactiveSequence>")
    assert [tree.tick_once() for _ in range(3)] == [R, R, F]
    assert bench.ticks["Check"] == 3
    assert bench.halts["Work"] == 1


def test_reactive_fallback_halts_a_running_child_when_an_earlier_one_succeeds(bench) -> None:
    bench.condition("Done", F, S)
    bench.stateful("Work", running_ticks=-1)
    tree = bench.tree("<ReactiveFallback><Done/><Work/></ReactiveFallback>")
    assert tree.tick_once() is R
    assert tree.tick_once() is S
    assert bench.halts["Work"] == 1


def test_sequence_with_memory_resumes_at_the_failed_child(bench) -> None:
    bench.action("A")
    bench.action("B", F, F, S)
    bench.action("C")
    tree = bench.tree("<SequenceWithMemory><A/><B/><C/></SequenceWithMemory>")
    assert [tree.tick_once() for _ in range(3)] == [F, F, S]
    assert (bench.ticks["A"], bench.ticks["B"], bench.ticks["C"]) == (1, 3, 1)


def test_sequence_with_memory_is_not_reset_by_halt(bench) -> None:
    bench.action("A")
    bench.stateful("Work", running_ticks=-1)
    tree = bench.tree("<SequenceWithMemory><A/><Work/></SequenceWithMemory>")
    assert tree.tick_once() is R
    tree.halt_tree()
    assert tree.tick_once() is R
    assert bench.ticks["A"] == 1


def test_async_sequence_yields_between_children(bench) -> None:
    bench.action("A")
    bench.action("B")
    sync = bench.tree("<Sequence><A/><B/></Sequence>")
    assert sync.tick_exactly_once() is S
    asynchronous = bench.tree("<AsyncSequence><A/><B/></AsyncSequence>")
    assert asynchronous.tick_exactly_once() is R  # yielded after A
    assert asynchronous.tick_exactly_once() is S
    again = bench.tree("<AsyncSequence><A/><B/></AsyncSequence>")
    assert again.tick_once() is S  # tick_once follows the wake-up signal


@pytest.mark.parametrize(
    ("success_count", "failure_count", "results", "expected"),
    [
        (-1, 1, (S, S, S), S),
        (-1, 1, (S, F, S), F),
        (2, 2, (S, F, S), S),
        (1, 3, (F, F, S), S),
        (3, 2, (S, F, F), F),
        (2, -1, (F, S, F), F),
    ],
)
def test_parallel_thresholds(bench, success_count, failure_count, results, expected) -> None:
    for name, result in zip("ABC", results, strict=True):
        bench.action(name, result)
    tree = bench.tree(
        f'<Parallel success_count="{success_count}" failure_count="{failure_count}"><A/><B/><C/></Parallel>'
    )
    assert tree.tick_once() is expected


def test_parallel_stops_ticking_once_a_threshold_is_reached_and_halts_runners(bench) -> None:
    bench.stateful("Slow", running_ticks=-1)
    bench.action("A")
    bench.action("B")
    bench.action("Late")
    tree = bench.tree('<Parallel success_count="2"><Slow/><A/><B/><Late/></Parallel>')
    assert tree.tick_once() is S
    assert bench.ticks["Late"] == 0
    assert bench.halts["Slow"] == 1


def test_parallel_with_all_children_skipped_succeeds(bench) -> None:
    tree = bench.tree('<Parallel><AlwaysSuccess _skipIf="true"/><AlwaysFailure _skipIf="true"/></Parallel>')
    assert tree.tick_once() is S


def test_parallel_impossible_threshold_fails_at_tick(bench) -> None:
    tree = bench.tree('<Parallel success_count="3"><AlwaysSuccess/></Parallel>')
    with pytest.raises(BTError, match="Can never succeed"):
        tree.tick_once()


@pytest.mark.parametrize(("max_failures", "expected"), [(1, F), (2, S), (-1, S)])
def test_parallel_all_waits_for_every_child(bench, max_failures: int, expected: NodeStatus) -> None:
    bench.stateful("Slow", running_ticks=2)
    bench.action("Bad", F)
    tree = bench.tree(
        f'<ParallelAll max_failures="{max_failures}"><Slow/><Bad/><AlwaysSuccess/></ParallelAll>'
    )
    assert tree.tick_once() is R
    assert tree.tick_once() is R
    assert tree.tick_once() is expected
    assert bench.ticks["Bad"] == 1


@pytest.mark.parametrize(
    ("condition", "children", "expected", "then_ticks", "else_ticks"),
    [
        (S, 3, S, 1, 0),
        (F, 3, F, 0, 1),
        (F, 2, F, 0, 0),
    ],
)
def test_if_then_else(bench, condition, children, expected, then_ticks, else_ticks) -> None:
    bench.condition("Cond", condition)
    bench.action("Then", S)
    bench.action("Else", F)
    body = "<Cond/><Then/>" + ("<Else/>" if children == 3 else "")
    tree = bench.tree(f"<IfThenElse>{body}</IfThenElse>")
    assert tree.tick_once() is expected
    assert (bench.ticks["Then"], bench.ticks["Else"]) == (then_ticks, else_ticks)


def test_if_then_else_does_not_re_check_the_condition_while_a_branch_runs(bench) -> None:
    bench.condition("Cond", S, F)
    bench.stateful("Work", running_ticks=1)
    tree = bench.tree("<IfThenElse><Cond/><Work/><AlwaysFailure/></IfThenElse>")
    assert tree.tick_once() is R
    assert tree.tick_once() is S
    assert bench.ticks["Cond"] == 1


def test_if_then_else_child_count_is_checked_when_ticked(bench) -> None:
    tree = bench.tree("<IfThenElse><AlwaysSuccess/></IfThenElse>")
    with pytest.raises(BTError, match="2 or 3 children"):
        tree.tick_once()


def test_while_do_else_is_reactive(bench) -> None:
    bench.condition("Cond", S, S, F)
    bench.stateful("Do", running_ticks=-1)
    bench.action("Else", S)
    tree = bench.tree("<WhileDoElse><Cond/><Do/><Else/></WhileDoElse>")
    assert [tree.tick_once() for _ in range(3)] == [R, R, S]
    assert bench.halts["Do"] == 1
    assert bench.ticks["Else"] == 1


def test_while_do_else_with_a_skipped_condition_raises(bench) -> None:
    tree = bench.tree('<WhileDoElse><AlwaysSuccess _skipIf="true"/><AlwaysSuccess/></WhileDoElse>')
    with pytest.raises(BTError, match="IDLE"):
        tree.tick_once()


@pytest.mark.parametrize(
    ("script", "expected_branch"),
    [
        ("v := 'b'", "B"),
        ("v := 42", "A"),  # an int entry reads as "42"
        ("v := 42.0", "A"),  # "42.000000" still matches "42" numerically
        ("v := '42abc'", "D"),  # 4.10 rejects trailing characters
        ("v := 'zzz'", "D"),
    ],
)
def test_switch_matching(bench, script: str, expected_branch: str) -> None:
    for name in "ABD":
        bench.action(name)
    tree = bench.tree(
        f'<Sequence><Script code="{script}"/>'
        '<Switch2 variable="{v}" case_1="42" case_2="b"><A/><B/><D/></Switch2></Sequence>'
    )
    assert tree.tick_once() is S
    assert {n for n in "ABD" if bench.ticks[n]} == {expected_branch}


def test_switch_uses_scripting_enums_and_halts_a_branch_it_leaves(bench) -> None:
    bench.factory.register_scripting_enum("RED", 1)
    bench.stateful("Red", running_ticks=-1)
    bench.action("Other")
    tree = bench.tree(
        '<Switch2 variable="{c}" case_1="RED" case_2="7"><Red/><AlwaysFailure/><Other/></Switch2>'
    )
    tree.root_blackboard.set("c", "1")
    assert tree.tick_once() is R
    tree.root_blackboard.set("c", "none")
    assert tree.tick_once() is S
    assert bench.halts["Red"] == 1


def test_try_catch_runs_the_catch_child_and_fails(bench) -> None:
    bench.action("Try1")
    bench.action("Catch")
    tree = bench.tree("<TryCatch><Try1/><AlwaysFailure/><Catch/></TryCatch>")
    assert tree.tick_once() is F
    assert (bench.ticks["Try1"], bench.ticks["Catch"]) == (1, 1)
    ok = bench.tree("<TryCatch><AlwaysSuccess/><Catch/></TryCatch>")
    assert ok.tick_once() is S
    assert bench.ticks["Catch"] == 1


def test_try_catch_on_halt(bench) -> None:
    bench.stateful("Work", running_ticks=-1)
    bench.action("Catch")
    tree = bench.tree('<TryCatch catch_on_halt="true"><Work/><Catch/></TryCatch>')
    assert tree.tick_once() is R
    tree.halt_tree()
    assert bench.ticks["Catch"] == 1
    assert bench.halts["Work"] == 1


def test_a_child_returning_idle_is_a_logic_error(bench) -> None:
    bench.action("Bad", NodeStatus.IDLE)
    tree = bench.tree("<Sequence><Bad/></Sequence>")
    with pytest.raises(BTError):
        tree.tick_once()


def test_navigation_with_recovery(bench) -> None:
    """A realistic recovery tree (after BT.CPP's navigation_test), with tick-based nodes."""
    from collections import Counter

    from kinema.bt import ConditionNode, StatefulActionNode, SyncActionNode

    stuck = {"value": False}
    ticks: Counter[str] = Counter()
    halted: list[str] = []

    class IsStuck(ConditionNode):
        def tick(self) -> NodeStatus:
            ticks[self.name] += 1
            return S if stuck["value"] else F

    class Instant(SyncActionNode):
        def tick(self) -> NodeStatus:
            ticks[self.name] += 1
            return S

    class FollowPath(StatefulActionNode):
        def on_start(self) -> NodeStatus:
            ticks[self.name] += 1
            self.left = 3
            return R

        def on_running(self) -> NodeStatus:
            self.left -= 1
            return S if self.left == 0 else R

        def on_halted(self) -> None:
            halted.append(self.name)

    for cls in (IsStuck, FollowPath):
        bench.factory.register_node_type(cls, cls.__name__)
    bench.factory.register_node_type(Instant, "ComputePathToPose")
    bench.factory.register_node_type(Instant, "BackUpAndSpin")
    xml = """
        <Fallback name="root">
            <ReactiveSequence name="navigation_subtree">
                <Inverter><Condition ID="IsStuck" name="stuck_1"/></Inverter>
                <SequenceWithMemory name="navigate">
                    <Action ID="ComputePathToPose" name="compute"/>
                    <Action ID="FollowPath" name="follow"/>
                </SequenceWithMemory>
            </ReactiveSequence>
            <SequenceWithMemory name="stuck_recovery">
                <Condition ID="IsStuck" name="stuck_2"/>
                <Action ID="BackUpAndSpin" name="backup"/>
            </SequenceWithMemory>
        </Fallback>"""
    tree = bench.tree(xml)
    statuses = [tree.tick_once() for _ in range(4)]
    assert statuses == [R, R, R, S]
    # SequenceWithMemory yields after "compute", so the first tick_once re-ticks the reactive condition
    assert ticks == Counter({"stuck_1": 5, "compute": 1, "follow": 1})
    assert halted == []

    ticks.clear()
    assert tree.tick_once() is R
    stuck["value"] = True
    assert tree.tick_once() is S
    assert ticks == Counter({"stuck_1": 3, "compute": 1, "follow": 1, "stuck_2": 1, "backup": 1})
    assert halted == ["follow"]


@pytest.mark.parametrize(
    ("base", "tag"),
    [
        ("SequenceNode", "Sequence"),
        ("FallbackNode", "Fallback"),
        ("ReactiveSequenceNode", "ReactiveSequence"),
        ("InverterNode", "Inverter"),
        ("AlwaysSuccessNode", "AlwaysSuccess"),
        ("ScriptNode", "Script"),
    ],
)
def test_a_subclass_of_a_built_in_node_that_overrides_tick_runs_its_override(
    bench, base: str, tag: str
) -> None:
    # The built-ins run their own tick() inline on the plain path; a subclass's tick() must still run,
    # conditions or not.
    from kinema.bt import actions, controls, decorators

    calls: list[str] = []

    def tick(self) -> NodeStatus:
        calls.append(self.name)
        return super(type(self), self).tick()

    counting = type(
        f"Counting{tag}",
        (next(getattr(m, base) for m in (actions, controls, decorators) if hasattr(m, base)),),
        {"tick": tick},
    )
    bench.factory.register_node_type(counting, "Counting")
    bench.action("A", F if tag == "Inverter" else S)
    body = "" if tag in ("AlwaysSuccess", "Script") else "<A/>"
    script = ' code="x := 1"' if tag == "Script" else ""
    tree = bench.tree(
        f'<Sequence><Counting name="plain"{script}>{body}</Counting>'
        f'<Counting name="hooked" _post="y := 2"{script}>{body}</Counting></Sequence>'
    )
    tree.tick_while_running()
    assert calls == ["plain", "hooked"]
