"""The objective server core (no transport): one run at a time, preemption, cancel, overrides, errors."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import pytest

from kinema.bt import BehaviorTreeFactory
from kinema.runtime.error_codes import MoveItErrorCode
from kinema.runtime.node_status import NodeStatusBatch, NodeStatusChange
from kinema.runtime.objective_server import (
    FactoryTreeSource,
    ObjectiveRequest,
    ObjectiveRun,
    ObjectiveServer,
)
from kinema.runtime.objective_status import ObjectiveStatus
from kinema.runtime.overrides import ParameterOverride
from kinema.runtime.result import ObjectiveResult

LIBRARY = """
<root BTCPP_format="4">
  <BehaviorTree ID="Quick">
    <Sequence><Script code="done := true"/></Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Forever">
    <KeepRunningUntilFailure><Sleep msec="20"/></KeepRunningUntilFailure>
  </BehaviorTree>
  <BehaviorTree ID="Fails">
    <Sequence name="main"><AlwaysSuccess/><AlwaysFailure name="broken"/></Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Typed">
    <Sequence>
      <Sleep msec="{delay}"/>
      <SetBlackboard value="{greeting}" output_key="echo"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Outer">
    <Sequence><SubTree ID="Inner" name="inner_call" msec="{outer_ms}"/></Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Inner">
    <Sleep msec="{msec}"/>
  </BehaviorTree>
  <BehaviorTree ID="Defaulted">
    <Sequence>
      <Sleep msec="{delay}"/>
      <SetBlackboard value="{greeting}" output_key="echo"/>
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <SubTree ID="Defaulted">
      <input_port name="delay" default="5"/>
      <input_port name="greeting" default="hi there"/>
      <inout_port name="echo" default="{echo}"/>
      <input_port name="unread" default="7"/>
    </SubTree>
  </TreeNodesModel>
</root>
"""


class Recorder:
    """A listener that keeps everything the server reports."""

    def __init__(self) -> None:
        self.statuses: list[tuple[ObjectiveStatus, str]] = []
        self.changes: list[NodeStatusChange] = []
        self.snapshots: list[list[tuple[str, str, str, object]]] = []
        self.results: list[ObjectiveResult] = []

    def on_status(self, status: ObjectiveStatus, objective_name: str) -> None:
        self.statuses.append((status, objective_name))

    def on_node_status(self, objective_name: str, changes: NodeStatusBatch) -> None:
        self.changes.extend(changes)

    def on_blackboard(self, objective_name: str, entries: list[tuple[str, str, str, object]]) -> None:
        self.snapshots.append(entries)

    def on_run_finished(self, run: ObjectiveRun, result: ObjectiveResult) -> None:
        self.results.append(result)


@pytest.fixture
def recorder() -> Recorder:
    return Recorder()


@pytest.fixture
def server(recorder: Recorder) -> Iterator[ObjectiveServer]:
    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(LIBRARY)
    with ObjectiveServer(FactoryTreeSource(factory), listeners=[recorder]) as running:
        yield running


def _wait_status(server: ObjectiveServer, status: ObjectiveStatus, timeout: float = 5.0) -> None:
    deadline = time.monotonic() + timeout
    while server.status[0] is not status:
        assert time.monotonic() < deadline, f"status stayed {server.status}"
        time.sleep(0.002)


def test_a_quick_objective_succeeds_and_reports_each_state(
    server: ObjectiveServer, recorder: Recorder
) -> None:
    result = server.submit(ObjectiveRequest("Quick")).wait(5)
    assert result == ObjectiveResult.success("Quick")
    assert [s for s, _ in recorder.statuses] == [
        ObjectiveStatus.LOADING,
        ObjectiveStatus.RUNNING,
        ObjectiveStatus.SUCCESS,
    ]
    # The final blackboard is always published (scope = the main tree's ID; scripts store numbers).
    assert ("Quick", "done", "double", 1.0) in recorder.snapshots[-1]


def test_a_run_answers_its_clients_before_the_listeners_hear_how_it_ended() -> None:
    """A goal's result (a done callback) leaves before the heartbeat, node status and log publications
    of the run's end; ``wait`` returns only once the listeners have heard everything."""
    events: list[object] = []

    class Watcher(Recorder):
        def on_status(self, status: ObjectiveStatus, objective_name: str) -> None:
            events.append(status)

        def on_node_status(self, objective_name: str, changes: NodeStatusBatch) -> None:
            events.append("node changes")

        def on_run_finished(self, run: ObjectiveRun, result: ObjectiveResult) -> None:
            events.append("finished")

    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(LIBRARY)
    with ObjectiveServer(FactoryTreeSource(factory), listeners=[Watcher()]) as server:
        run = server.submit(
            ObjectiveRequest("Quick"),
            before_start=lambda r: r.add_done_callback(lambda _: events.append("answered")),
        )
        assert run.wait(5) == ObjectiveResult.success("Quick")
        assert events == [
            ObjectiveStatus.LOADING,
            ObjectiveStatus.RUNNING,
            "answered",
            "node changes",
            ObjectiveStatus.SUCCESS,
            "finished",
        ]


def test_running_callbacks_come_after_a_first_tick_that_did_not_end_the_run(server: ObjectiveServer) -> None:
    called: list[str] = []
    quick = server.submit(
        ObjectiveRequest("Quick"),
        before_start=lambda r: r.add_running_callback(lambda: called.append("Quick")),
    )
    assert quick.wait(5) == ObjectiveResult.success("Quick")
    forever = server.submit(
        ObjectiveRequest("Forever"),
        before_start=lambda r: r.add_running_callback(lambda: called.append("Forever")),
    )
    _wait_status(server, ObjectiveStatus.RUNNING)
    deadline = time.monotonic() + 5
    while not called and time.monotonic() < deadline:
        time.sleep(0.002)
    forever.add_running_callback(lambda: called.append("late"))  # registered after: called at once
    assert called == ["Forever", "late"]
    assert server.cancel()


def test_cancel_halts_a_looping_objective_within_a_tick(server: ObjectiveServer) -> None:
    run = server.submit(ObjectiveRequest("Forever"))
    _wait_status(server, ObjectiveStatus.RUNNING)
    started = time.monotonic()
    assert server.cancel()
    result = run.wait(5)
    assert result is not None and result.cancelled
    assert result.error_code == MoveItErrorCode.PREEMPTED
    # Well under a tick period plus 100 ms when the machine is not overloaded (benchmarks/cancel_latency.py
    # measures it); this bound only catches a cancel that waits for something that never comes.
    assert time.monotonic() - started < 5.0
    assert server.status == (ObjectiveStatus.CANCELLED, "Forever")
    assert not server.cancel()  # nothing runs any more


def test_a_new_request_preempts_the_running_one(server: ObjectiveServer) -> None:
    first = server.submit(ObjectiveRequest("Forever"))
    _wait_status(server, ObjectiveStatus.RUNNING)
    second = server.submit(ObjectiveRequest("Quick"))
    assert second.wait(5) == ObjectiveResult.success("Quick")
    first_result = first.wait(5)
    assert first_result is not None and first_result.cancelled
    assert "newer" in first_result.error_message


def test_failure_names_the_failing_node_path(server: ObjectiveServer) -> None:
    result = server.submit(ObjectiveRequest("Fails")).wait(5)
    assert result is not None and result.error_code == MoveItErrorCode.FAILURE
    assert result.error_message == "objective 'Fails' failed: node 'broken' [AlwaysFailure] returned FAILURE"


def test_a_failure_note_from_the_behavior_is_the_message(server: ObjectiveServer, recorder: Recorder) -> None:
    # The agent forwards a behavior's publish_failure toast; the node path ties it to the failing node.
    factory = server._source.factory()  # type: ignore[attr-defined]
    factory.register_simple_action("Grumpy", lambda node: _note_and_fail(server, node))
    xml = '<root BTCPP_format="4"><BehaviorTree ID="G"><Grumpy name="g"/></BehaviorTree></root>'
    result = server.submit(ObjectiveRequest(objective_xml=xml)).wait(5)
    assert result is not None
    assert result.error_message == "objective 'G' failed: node 'g' [Grumpy]: gripper is jammed"


def _note_and_fail(server: ObjectiveServer, node: object) -> object:
    from kinema.bt import NodeStatus

    server.note_failure(node.full_path, "gripper is jammed")  # type: ignore[attr-defined]
    return NodeStatus.FAILURE


def test_unknown_objective_lists_the_alternatives(server: ObjectiveServer) -> None:
    result = server.submit(ObjectiveRequest("Quik")).wait(5)
    assert result is not None and result.failed
    assert "unknown objective 'Quik'" in result.error_message and "Quick" in result.error_message
    assert server.status[0] is ObjectiveStatus.FAILURE


@pytest.mark.parametrize(
    ("xml", "reason"),
    [
        ("<root><BehaviorTree ID='X'><Nope/></BehaviorTree></root>", "Nope"),
        ("this is not xml", "XML"),
        ("", "no objective"),
        ("<" * (3 * 1024 * 1024), "limit"),
    ],
)
def test_malformed_xml_fails_with_a_reason_and_the_server_keeps_serving(
    server: ObjectiveServer, xml: str, reason: str
) -> None:
    result = server.submit(ObjectiveRequest(objective_xml=xml)).wait(10)
    assert result is not None and result.failed
    assert reason in result.error_message
    assert server.submit(ObjectiveRequest("Quick")).wait(5) == ObjectiveResult.success("Quick")


def test_the_name_wins_over_the_xml(server: ObjectiveServer) -> None:
    run = server.submit(ObjectiveRequest("Quick", objective_xml="garbage"))
    assert run.wait(5) == ObjectiveResult.success("Quick")


def test_adhoc_xml_does_not_replace_library_objectives(server: ObjectiveServer) -> None:
    shadow = '<root BTCPP_format="4"><BehaviorTree ID="Quick"><AlwaysFailure/></BehaviorTree></root>'
    result = server.submit(ObjectiveRequest(objective_xml=shadow)).wait(5)
    assert result is not None and result.failed
    assert server.submit(ObjectiveRequest("Quick")).wait(5) == ObjectiveResult.success("Quick")


def test_overrides_are_typed_by_the_port_that_reads_them(server: ObjectiveServer) -> None:
    overrides = (ParameterOverride("delay", "10"), ParameterOverride("greeting", "hello"))
    assert server.submit(ObjectiveRequest("Typed", overrides=overrides)).wait(5) == ObjectiveResult.success(
        "Typed"
    )


@pytest.mark.parametrize(
    ("overrides", "reason"),
    [
        ((ParameterOverride("delay", "soon"),), "'soon' is not a valid"),
        ((ParameterOverride("dealy", "10"),), "delay"),
        ((ParameterOverride("delay", "10", ("nowhere",)),), "no subtree is named 'nowhere'"),
    ],
)
def test_bad_overrides_reject_the_request_before_the_first_tick(
    server: ObjectiveServer, recorder: Recorder, overrides: tuple[ParameterOverride, ...], reason: str
) -> None:
    result = server.submit(ObjectiveRequest("Typed", overrides=overrides)).wait(5)
    assert result is not None and result.failed
    assert reason in result.error_message
    assert ObjectiveStatus.RUNNING not in [s for s, _ in recorder.statuses]
    assert recorder.changes == []


def _echo(recorder: Recorder) -> object:
    return next(value for scope, key, _, value in recorder.snapshots[-1] if key == "echo")


def test_an_objective_run_on_its_own_reads_the_defaults_of_its_ports_and_overrides_replace_them(
    server: ObjectiveServer, recorder: Recorder
) -> None:
    # As if it were a <SubTree ID="Defaulted"/> with no attributes: "delay" and "greeting" come from
    # the model; "unread" is read by no port, "{echo}" wires the key of its name (nothing to seed).
    assert server.submit(ObjectiveRequest("Defaulted")).wait(5) == ObjectiveResult.success("Defaulted")
    assert _echo(recorder) == "hi there"
    overrides = (ParameterOverride("greeting", "hello"),)
    result = server.submit(ObjectiveRequest("Defaulted", overrides=overrides)).wait(5)
    assert result == ObjectiveResult.success("Defaulted")
    assert _echo(recorder) == "hello"
    # A bad override is still refused, default or not.
    soon = (ParameterOverride("delay", "soon"),)
    bad = server.submit(ObjectiveRequest("Defaulted", overrides=soon)).wait(5)
    assert bad is not None and bad.failed and "'soon' is not a valid" in bad.error_message


def test_an_adhoc_document_s_main_tree_reads_the_defaults_its_model_declares(
    server: ObjectiveServer, recorder: Recorder
) -> None:
    xml = """<root BTCPP_format="4" main_tree_to_execute="Greets">
      <BehaviorTree ID="Greets"><SetBlackboard value="{greeting}" output_key="echo"/></BehaviorTree>
      <TreeNodesModel>
        <SubTree ID="Greets"><input_port name="greeting" default="ahoy"/></SubTree>
      </TreeNodesModel>
    </root>"""
    assert server.submit(ObjectiveRequest(objective_xml=xml)).wait(5) == ObjectiveResult.success("Greets")
    assert _echo(recorder) == "ahoy"
    # Without a model, a key nobody wrote is still missing (BT.CPP's own semantics).
    result = server.submit(ObjectiveRequest("Typed")).wait(5)
    assert result is not None and result.failed and "Missing parameter [msec]" in result.error_message


def test_an_override_no_port_reads_suggests_the_objective_s_parameters_not_its_inner_keys(
    server: ObjectiveServer,
) -> None:
    # It listed every key of the blackboard, the outputs the objective's behaviors write included.
    xml = """<root BTCPP_format="4" main_tree_to_execute="Copies">
      <BehaviorTree ID="Copies">
        <Sequence>
          <SetBlackboard value="{amount}" output_key="copy"/>
          <LoopDouble queue="1;2" value="{inner_result}"><AlwaysSuccess/></LoopDouble>
        </Sequence>
      </BehaviorTree>
      <TreeNodesModel>
        <SubTree ID="Copies"><input_port name="amount" default="1"/></SubTree>
      </TreeNodesModel>
    </root>"""
    overrides = (ParameterOverride("amout", "2"),)
    result = server.submit(ObjectiveRequest(objective_xml=xml, overrides=overrides)).wait(5)
    assert result is not None and result.failed
    assert "no port of the objective reads the blackboard key 'amout'; did you mean 'amount'?" in (
        result.error_message
    ), result.error_message
    assert "inner_result" not in result.error_message


def test_namespaced_overrides_reach_only_that_subtree(server: ObjectiveServer) -> None:
    overrides = (ParameterOverride("msec", "5", ("inner_call",)),)
    ok = server.submit(ObjectiveRequest("Outer", overrides=overrides)).wait(5)
    # The subtree maps msec to {outer_ms}, so the value lands in the root key outer_ms.
    assert ok == ObjectiveResult.success("Outer")


def test_a_burst_of_requests_leaves_the_server_idle_and_responsive(server: ObjectiveServer) -> None:
    runs = []
    for index in range(200):
        runs.append(server.submit(ObjectiveRequest("Forever")))
        if index % 2:
            server.cancel(reason="burst cancel", timeout=0)
    server.cancel()
    results = [run.wait(5) for run in runs]
    assert all(result is not None and result.cancelled for result in results)
    assert server.status[0] in (ObjectiveStatus.CANCELLED, ObjectiveStatus.IDLE)
    assert server.submit(ObjectiveRequest("Quick")).wait(5) == ObjectiveResult.success("Quick")


def test_node_status_changes_carry_paths(server: ObjectiveServer, recorder: Recorder) -> None:
    server.submit(ObjectiveRequest("Fails")).wait(5)
    paths = {change.node_path for change in recorder.changes}
    assert {"main", "broken"} <= paths


def test_call_soon_runs_between_ticks(server: ObjectiveServer) -> None:
    seen: list[str] = []
    server.submit(ObjectiveRequest("Forever"))
    _wait_status(server, ObjectiveStatus.RUNNING)
    assert server.call_soon(lambda: seen.append(threading.current_thread().name) or 7) == 7
    assert seen == ["kinema-tick"]
    server.cancel()


def test_stopping_fails_the_running_objective_with_the_reason(recorder: Recorder) -> None:
    """A runtime that stops is not a cancel the objective's client asked for: never PREEMPTED."""
    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(LIBRARY)
    server = ObjectiveServer(FactoryTreeSource(factory), listeners=[recorder])
    server.start()
    run = server.submit(ObjectiveRequest("Forever"))
    _wait_status(server, ObjectiveStatus.RUNNING)
    server.stop(reason="the agent stopped")
    result = run.result
    assert result is not None and result.failed and result.error_message == "the agent stopped", result


def test_an_abort_fails_the_running_objective_naming_what_died(recorder: Recorder) -> None:
    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(LIBRARY)
    with ObjectiveServer(FactoryTreeSource(factory), listeners=[recorder]) as server:
        run = server.submit(ObjectiveRequest("Forever"))
        _wait_status(server, ObjectiveStatus.RUNNING)
        assert server.abort("driver 'arm' went away")
        result = run.wait(5)
        assert result is not None and result.failed and "driver 'arm' went away" in result.error_message
        assert server.status == (ObjectiveStatus.FAILURE, "Forever")


def test_the_final_status_is_held_then_the_server_reports_idle(recorder: Recorder) -> None:
    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(LIBRARY)
    with ObjectiveServer(FactoryTreeSource(factory), listeners=[recorder], result_hold_s=0.05) as server:
        server.submit(ObjectiveRequest("Quick")).wait(5)
        _wait_status(server, ObjectiveStatus.IDLE)
    assert [s for s, _ in recorder.statuses] == [
        ObjectiveStatus.LOADING,
        ObjectiveStatus.RUNNING,
        ObjectiveStatus.SUCCESS,
        ObjectiveStatus.IDLE,
    ]
    assert recorder.statuses[-1] == (ObjectiveStatus.IDLE, "Quick")


def test_a_missing_parameter_without_a_default_is_named_in_the_failure() -> None:
    from kinema.behaviors import NodeStatus as Status
    from kinema.behaviors import SyncBehavior, input_port
    from kinema.testing import registry_of

    class LooksUp(SyncBehavior):
        """Reads a waypoint name."""

        @classmethod
        def provided_ports(cls):  # type: ignore[no-untyped-def]
            return [input_port("waypoint", str)]

        def tick(self) -> Status:
            self.get_required_inputs("waypoint")
            return Status.SUCCESS

    factory = registry_of([LooksUp]).create_factory()
    factory.register_behavior_tree_from_text(
        """<root BTCPP_format="4">
          <BehaviorTree ID="Go"><Action ID="LooksUp" waypoint="{waypoint_name}"/></BehaviorTree>
          <TreeNodesModel>
            <SubTree ID="Go"><input_port name="waypoint_name" default=""/></SubTree>
          </TreeNodesModel>
        </root>"""
    )
    with ObjectiveServer(FactoryTreeSource(factory)) as running:
        result = running.submit(ObjectiveRequest("Go")).wait(5)
        assert result is not None and result.failed
        assert "unable to find the key [waypoint] remapped to [waypoint_name]" in result.error_message
        # What to do first, then where the tree missed it.
        assert result.error_message.startswith(
            "'waypoint_name' is a parameter of objective 'Go' without a default"
        )
        assert "-p waypoint_name=VALUE" in result.error_message
        given = (ParameterOverride("waypoint_name", "Home"),)
        assert running.submit(ObjectiveRequest("Go", overrides=given)).wait(5) == ObjectiveResult.success(
            "Go"
        )
