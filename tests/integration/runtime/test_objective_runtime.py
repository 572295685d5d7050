"""The objective server in its own process, driven through the SDK over zenoh."""

from __future__ import annotations

import itertools
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from kinema.errors import TransportError
from kinema.sdk import (
    MoveItErrorCode,
    ObjectiveClient,
    ObjectiveResult,
    ObjectiveStatus,
    ObjectiveTimeoutError,
    ParameterOverride,
)

TEST_SIMPLE = """<root BTCPP_format="4" main_tree_to_execute="test simple">
  <BehaviorTree ID="test simple">
    <Control ID="Sequence" name="TopLevelSequence">
      <Action ID="AlwaysSuccess"/>
    </Control>
  </BehaviorTree>
</root>"""


def _wait_for(
    client: ObjectiveClient, status: ObjectiveStatus, name: str | None = None, timeout: float = 10
) -> None:
    deadline = time.monotonic() + timeout
    with client.statuses(timeout=timeout) as stream:
        for heartbeat in stream:
            if heartbeat.status is status and (name is None or heartbeat.objective_name == name):
                return
            assert time.monotonic() < deadline, f"never saw {status}"
    raise AssertionError(f"never saw {status} {name or ''}")


def test_the_tutorial_xml_sent_to_do_objective_succeeds_with_code_1(client: ObjectiveClient) -> None:
    handle = client.start(xml=TEST_SIMPLE)
    result = handle.result(10)
    assert result == ObjectiveResult(1, "", "test simple")
    assert handle.status == "SUCCEEDED"


def test_cancel_stops_a_looping_objective(client: ObjectiveClient) -> None:
    handle = client.start("Forever")
    _wait_for(client, ObjectiveStatus.RUNNING, "Forever")
    assert handle.cancel()
    result = handle.result(5)
    assert result.cancelled and result.error_code == MoveItErrorCode.PREEMPTED
    assert handle.status == "CANCELED"
    assert client.status().status in (ObjectiveStatus.CANCELLED, ObjectiveStatus.IDLE)


def _stops_running(client: ObjectiveClient, timeout: float = 5) -> None:
    deadline = time.monotonic() + timeout
    while client.status(timeout=timeout).status in (ObjectiveStatus.RUNNING, ObjectiveStatus.LOADING):
        assert time.monotonic() < deadline, f"still {client.status(timeout=timeout)}"
        time.sleep(0.05)


def test_waiting_with_a_timeout_cancels_the_objective_when_it_passes(client: ObjectiveClient) -> None:
    with pytest.raises(ObjectiveTimeoutError, match=r"'Forever' did not end within 0\.5 s; it was cancelled"):
        client.execute("Forever", timeout=0.5)
    _stops_running(client)
    with pytest.raises(ObjectiveTimeoutError, match=r"did not end within 0\.5 s"):
        client.do_xml(
            TEST_SIMPLE.replace('<Action ID="AlwaysSuccess"/>', '<SubTree ID="Forever"/>'), timeout=0.5
        )
    _stops_running(client)
    assert client.execute("Quick", timeout=10).succeeded  # in time: its result, as without a timeout


def test_interrupting_a_wait_cancels_the_objective(agent: Any, client: ObjectiveClient) -> None:
    # Ctrl-C in a script blocked in execute(): the objective must not keep the robot moving.
    from kinema.sdk import QuickClient

    main = threading.main_thread()

    def waiting_for_the_result() -> bool:
        frame = sys._current_frames().get(main.ident or 0)
        while frame is not None:
            if frame.f_code.co_name == "_wait_or_cancel":
                return True
            frame = frame.f_back
        return False

    def interrupt_once_it_runs() -> None:
        # The signal comes once execute() waits for the result (the run has started), as a user's would.
        with QuickClient(agent.endpoint, timeout=10) as quick:
            deadline = time.monotonic() + 30
            while quick.status() != (ObjectiveStatus.RUNNING, "Forever") and time.monotonic() < deadline:
                time.sleep(0.02)
        deadline = time.monotonic() + 30
        while not waiting_for_the_result() and time.monotonic() < deadline:
            time.sleep(0.01)
        os.kill(os.getpid(), signal.SIGINT)

    if threading.current_thread() is not threading.main_thread():
        pytest.skip("Ctrl-C reaches only the main thread, and this test runs in another")
    # Python raises KeyboardInterrupt on SIGINT unless it started with SIGINT ignored, as everything a
    # non-interactive shell starts in the background does: a user's terminal has the default handler.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        interrupter = threading.Thread(target=interrupt_once_it_runs, daemon=True)
        interrupter.start()
        with pytest.raises(KeyboardInterrupt):
            client.execute("Forever", timeout=60)
        interrupter.join(5)
    finally:
        signal.signal(signal.SIGINT, previous)
    _stops_running(client)


def test_sigterm_to_kinema_objective_run_cancels_the_objective(agent: Any, client: ObjectiveClient) -> None:
    """`timeout 60 kinema objective run ...` ended the command with SIGTERM and left the objective running:
    the robot went on moving for a command that was gone."""
    command = subprocess.Popen(
        [sys.executable, "-m", "kinema", "objective", "run", "Forever", "--connect", agent.endpoint],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        _wait_for(client, ObjectiveStatus.RUNNING, "Forever")
        time.sleep(1.0)  # the command has its acceptance and waits for the result (the heartbeat may lead)
        command.send_signal(signal.SIGTERM)
        _out, err = command.communicate(timeout=20)
    finally:
        command.kill()
    assert "cancelling 'Forever'" in err, err
    assert command.returncode == 1
    _stops_running(client)


def test_cancel_objective_service_halts_what_runs(client: ObjectiveClient) -> None:
    handle = client.start("Forever")
    _wait_for(client, ObjectiveStatus.RUNNING, "Forever")
    assert client.cancel()
    assert handle.result(5).cancelled
    assert not client.cancel()


def test_a_new_goal_preempts_the_old_one(client: ObjectiveClient) -> None:
    first = client.start("Forever")
    _wait_for(client, ObjectiveStatus.RUNNING, "Forever")
    second = client.execute("Quick")
    assert second == ObjectiveResult.success("Quick")
    preempted = first.result(5)
    assert preempted.cancelled and "newer" in preempted.error_message


def test_valid_overrides_apply(client: ObjectiveClient) -> None:
    result = client.execute("Typed", {"delay": "10", "greeting": "hello"})
    assert result == ObjectiveResult.success("Typed")
    typed = client.execute("Typed", {"delay": 5, "greeting": "[1, 2]"})
    assert typed.succeeded


def test_a_goal_sent_again_is_the_one_asked_for(client: ObjectiveClient) -> None:
    # The client keeps the last goal sent without overrides serialised: it must never stand in for
    # another objective, another XML document, or a call that gives overrides.
    given = {"delay": "1", "greeting": "hello"}
    for _ in range(2):
        assert client.execute("Typed", given).succeeded
        bare = client.execute("Typed")
        assert bare.failed and "msec" in bare.error_message, bare
    assert client.execute("Quick").succeeded
    failing = TEST_SIMPLE.replace("AlwaysSuccess", "AlwaysFailure")
    for _ in range(2):
        assert client.do_xml(TEST_SIMPLE).succeeded
        assert client.do_xml(failing).failed


@pytest.mark.parametrize(
    ("overrides", "reason"),
    [
        ({"delay": "soon", "greeting": "x"}, "'soon' is not a valid unsigned int"),
        ({"delay": 1.5, "greeting": "x"}, "1.5 is not an int"),
        ({"dealy": "5"}, "did you mean 'delay'"),
        ([ParameterOverride("delay", "5", ("nowhere",))], "no subtree is named 'nowhere'"),
    ],
)
def test_invalid_overrides_fail_before_the_objective_runs(
    client: ObjectiveClient, overrides: object, reason: str
) -> None:
    result = client.execute("Typed", overrides)  # type: ignore[arg-type]
    assert result.failed and reason in result.error_message
    assert "Typed" in result.error_message


def test_heartbeat_walks_through_the_states(client: ObjectiveClient) -> None:
    seen: list[ObjectiveStatus] = []
    with client.statuses(timeout=10) as stream:
        handle = client.start("Short Sleep")
        for heartbeat in stream:
            if not seen or seen[-1] is not heartbeat.status:
                seen.append(heartbeat.status)
            if heartbeat.status is ObjectiveStatus.IDLE and ObjectiveStatus.SUCCESS in seen:
                break
    assert handle.result(5).succeeded
    start = seen.index(ObjectiveStatus.LOADING)
    assert seen[start:] == [
        ObjectiveStatus.LOADING,
        ObjectiveStatus.RUNNING,
        ObjectiveStatus.SUCCESS,
        ObjectiveStatus.IDLE,
    ]


def test_heartbeat_comes_at_10_hz(client: ObjectiveClient) -> None:
    stamps = []
    with client.statuses(timeout=5) as stream:
        for heartbeat in stream:
            stamps.append(heartbeat.process_time)
            if len(stamps) == 21:
                break
    # The median period, stamped by the runtime: a stall on a busy machine stretches a few periods only.
    periods = sorted(b - a for a, b in itertools.pairwise(stamps))
    median = periods[len(periods) // 2]
    assert 0.05 < median < 0.3, periods


def test_failure_names_the_node_and_reaches_the_log_stream(client: ObjectiveClient) -> None:
    with client.logs(timeout=5) as logs:
        result = client.execute("Fails")
        assert result.error_code == MoveItErrorCode.FAILURE
        assert "node 'broken' [AlwaysFailure]" in result.error_message
        entry = next(iter(logs))
    assert entry.level == "error" and "broken" in entry.text


def test_the_blackboard_snapshot_is_latched(client: ObjectiveClient) -> None:
    assert client.execute("Quick").succeeded
    with client.blackboard(timeout=5) as stream:
        snapshot = next(iter(stream))
    assert snapshot.objective_name == "Quick"
    assert snapshot.as_dict()["Quick"]["answer"] == "42"


def test_node_status_changes_are_streamed(client: ObjectiveClient) -> None:
    with client.node_statuses(timeout=5) as stream:
        assert client.execute("Fails").failed
        paths = set()
        for batch in stream:
            paths.update(change.node_path for change in batch.changes)
            if "broken" in paths:
                break
    assert {"main", "broken"} <= paths


def test_the_objective_list_carries_metadata(client: ObjectiveClient) -> None:
    names = {info.name: info for info in client.objectives()}
    assert {"Quick", "Forever", "Fails", "Typed", "Short Sleep"} <= set(names)
    assert names["Quick"].file_path.endswith("builtins.xml")


def test_a_client_killed_mid_goal_does_not_wedge_the_server(agent: Any, client: ObjectiveClient) -> None:
    script = textwrap.dedent(
        f"""
        import sys, time
        from kinema.sdk import ObjectiveClient
        client = ObjectiveClient({agent.endpoint!r}, timeout=10)
        handle = client.start("Forever")
        print("started", flush=True)
        handle.result()
        """
    )
    victim = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    try:
        assert victim.stdout is not None and victim.stdout.readline().strip() == "started"
        _wait_for(client, ObjectiveStatus.RUNNING, "Forever")
        os.kill(victim.pid, signal.SIGKILL)
        victim.wait(5)
    finally:
        if victim.poll() is None:
            victim.kill()
    assert client.execute("Quick") == ObjectiveResult.success("Quick")
    handle = client.start("Forever")
    _wait_for(client, ObjectiveStatus.RUNNING, "Forever")
    assert handle.cancel() and handle.result(5).cancelled


def test_a_burst_of_200_execute_and_cancel_requests_leaves_the_server_idle(client: ObjectiveClient) -> None:
    from kinema.runtime import names

    execute = client.node.create_client(names.EXECUTE_OBJECTIVE_TYPE, names.EXECUTE_OBJECTIVE)
    cancel = client.node.create_client(names.CANCEL_OBJECTIVE_TYPE, names.CANCEL_OBJECTIVE)
    futures = []
    for index in range(100):
        name = "Forever" if index % 3 else "Quick"
        futures.append(execute.call_async({"objective_name": name}, timeout=60))
        futures.append(cancel.call_async({}, timeout=60))
    responses = [future.result(60) for future in futures]
    codes = {int(r.error_code.val) for r in responses[0::2]}
    assert codes <= {MoveItErrorCode.SUCCESS, MoveItErrorCode.PREEMPTED}
    client.cancel()
    _wait_for(client, ObjectiveStatus.IDLE, timeout=15)
    assert client.execute("Quick") == ObjectiveResult.success("Quick")


@pytest.mark.parametrize(
    ("xml", "reason"),
    [
        ("<root BTCPP_format='4'><BehaviorTree ID='X'><NoSuchNode/></BehaviorTree></root>", "NoSuchNode"),
        ("<root><BehaviorTree ID='X'><Sequence>", "XML"),
        ("x" * (10 * 1024 * 1024), "limit is"),
    ],
    ids=["unknown node", "broken XML", "10 MB"],
)
def test_malformed_xml_gets_an_error_result_and_the_server_keeps_serving(
    client: ObjectiveClient, xml: str, reason: str
) -> None:
    result = client.do_xml(xml, timeout=30)
    assert isinstance(result, ObjectiveResult) and result.failed
    assert reason in result.error_message
    assert client.execute("Quick").succeeded


def test_unknown_objectives_and_wrong_types_get_error_results(client: ObjectiveClient) -> None:
    from kinema.runtime import names

    unknown = client.execute("Quik")
    assert unknown.failed and "did you mean 'Quick'" in unknown.error_message
    execute = client.node.create_client(names.EXECUTE_OBJECTIVE_TYPE, names.EXECUTE_OBJECTIVE)
    bad_type = execute.call(
        {"objective_name": "Typed", "parameter_overrides": [{"description": {"name": "delay", "type": 9}}]},
        timeout=10,
    )
    assert bad_type.error_code.val == MoveItErrorCode.FAILURE and "type 9" in bad_type.error_code.message
    garbage = client.node.session.zenoh.get(
        f"{client.node.session.domain_id}/execute_objective/**", payload=b"\x00\x01\x02", timeout=5
    )
    replies = list(garbage)
    assert replies and all(reply.err is not None for reply in replies)
    assert client.execute("Quick").succeeded


def test_no_runtime_gives_a_clear_transport_error(free_endpoint: str) -> None:
    with pytest.raises(TransportError, match="no Kinema router answers"):
        ObjectiveClient(free_endpoint, timeout=0.5)


def test_the_cli_exits_non_zero_with_one_line_when_no_runtime_answers(free_endpoint: str) -> None:
    endpoint = free_endpoint
    for verb in (["status"], ["run", "Quick"], ["cancel"]):
        done = subprocess.run(
            [sys.executable, "-m", "kinema", "objective", *verb, "--connect", endpoint, "--timeout", "0.5"],
            capture_output=True,
            text=True,
            timeout=30,
        )
        assert done.returncode == 1
        assert done.stderr.count("\n") == 1 and done.stderr.startswith("error: no Kinema router answers")


def test_the_cli_runs_and_reports_objectives(agent: Any, tmp_path: object) -> None:
    def kinema(*args: str, stdin: str | None = None) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [sys.executable, "-m", "kinema", "objective", *args, "--connect", agent.endpoint],
            capture_output=True,
            text=True,
            input=stdin,
            timeout=60,
        )

    ok = kinema("run", "Typed", "--param", "delay=5", "--param", "greeting=hi")
    assert ok.returncode == 0 and "succeeded" in ok.stdout
    failed = kinema("run", "Fails")
    assert failed.returncode == 1 and "node 'broken'" in failed.stderr
    adhoc = kinema("do", "-", stdin=TEST_SIMPLE)
    assert adhoc.returncode == 0 and "'test simple' succeeded" in adhoc.stdout
    broken = Path(str(tmp_path), "broken.xml")
    broken.write_text('<root BTCPP_format="4"><BehaviorTree ID="x"><Sequence></BehaviorTree></root>')
    malformed = kinema("do", str(broken))
    assert malformed.returncode == 1 and f"{broken}:1: XML syntax error" in malformed.stderr, malformed.stderr
    started = kinema("run", "Forever", "--no-wait")
    assert started.returncode == 0
    status = kinema("status")
    assert status.stdout.strip() in ("Running: Forever", "Loading: Forever")
    cancelled = kinema("cancel")
    assert cancelled.returncode == 0 and "cancelled 'Forever'" in cancelled.stdout


def test_objective_run_prints_the_toasts_of_its_behaviors(lab_sim_agent: Any) -> None:
    tree = """<root BTCPP_format="4" main_tree_to_execute="Toasts">
      <BehaviorTree ID="Toasts">
        <Sequence>
          <Action ID="LogMessage" name="hello" message="Sum: 5"/>
          <Action ID="LogMessage" name="careful" message="mind the gap" log_level="warn"/>
        </Sequence>
      </BehaviorTree>
    </root>"""
    done = subprocess.run(
        [sys.executable, "-m", "kinema", "objective", "do", "-", "--connect", lab_sim_agent.endpoint],
        capture_output=True,
        text=True,
        input=tree,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[-1] == "objective 'Toasts' succeeded"
    assert any(line.endswith("Sum: 5") and "hello" in line for line in lines[:-1]), done.stdout
    assert "warning: " in done.stderr and "mind the gap" in done.stderr


def test_the_json_endpoints_start_cancel_and_refuse_garbage(agent: Any) -> None:
    from kinema.runtime import quick_protocol
    from kinema.sdk import QuickClient

    with QuickClient(agent.endpoint, timeout=10) as quick:
        run = quick.start("Typed", {"delay": "5", "greeting": "hi"})
        assert run.result() == ObjectiveResult.success("Typed")
        looping = quick.start("Forever")
        deadline = time.monotonic() + 5
        while quick.status() != (ObjectiveStatus.RUNNING, "Forever"):
            assert time.monotonic() < deadline
            time.sleep(0.01)
        assert looping.cancel()
        assert looping.result().cancelled
        assert not looping.cancel()
        replies = list(
            quick._session.get(
                quick_protocol.key(quick.domain_id, quick_protocol.START), payload=b"{nope", timeout=5
            )
        )
        assert len(replies) == 1 and "bad request" in replies[0].err.payload.to_string()
        assert quick.start("Quick").result().succeeded


def test_deeply_nested_json_on_the_quick_keys_gets_an_answer(agent: Any) -> None:
    """It raised RecursionError in the agent's handler, and the client got no answer at all."""
    from kinema.runtime import quick_protocol
    from kinema.sdk import QuickClient

    deep = b"[" * 100_000 + b"]" * 100_000
    with QuickClient(agent.endpoint, timeout=10) as quick:
        for operation in (quick_protocol.START, quick_protocol.START_XML, quick_protocol.CANCEL):
            replies = list(
                quick._session.get(
                    quick_protocol.key(quick.domain_id, operation),
                    payload=b'{"objective_name": "Quick", "overrides": ' + deep + b"}",
                    timeout=10,
                )
            )
            assert len(replies) == 1 and "levels deep" in replies[0].err.payload.to_string(), operation
        assert quick.start("Quick").result().succeeded


def test_the_name_only_doors_refuse_xml(agent: Any, client: ObjectiveClient) -> None:
    """What an operator's certificate reaches runs library objectives by name; XML is a grant of its own."""
    from kinema.runtime import names, quick_protocol
    from kinema.sdk import QuickClient

    xml = '<root BTCPP_format="4"><BehaviorTree ID="X"><AlwaysSuccess/></BehaviorTree></root>'
    with QuickClient(agent.endpoint, timeout=10) as quick:
        replies = list(
            quick._session.get(
                quick_protocol.key(quick.domain_id, quick_protocol.START),
                payload=quick_protocol.encode({"objective_xml": xml}),
                timeout=5,
            )
        )
        assert len(replies) == 1 and "by name only" in replies[0].err.payload.to_string()
        assert quick.start(xml=xml).result().succeeded  # start_xml
    by_name = client.node.create_action_client(names.DO_OBJECTIVE_TYPE, names.RUN_OBJECTIVE)
    assert by_name.wait_for_server(10)
    refused = by_name.send_goal({"objective_xml_string": xml}, timeout=10).result(10).result
    assert "by name only" in refused.error_message and refused.error_code.val != 1
    assert client.execute("Quick").succeeded and client._by_name  # the SDK's names go through it
    assert client.do_xml(xml).succeeded


def test_a_router_without_an_agent_is_reported_after_the_timeout(free_endpoint: str) -> None:
    from kinema.transport import host_router

    with host_router(free_endpoint):
        started = time.monotonic()
        done = subprocess.run(
            [
                sys.executable,
                "-m",
                "kinema",
                "objective",
                "run",
                "Quick",
                "--connect",
                free_endpoint,
                "--timeout",
                "1",
            ],
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert done.returncode == 1
        assert (
            done.stderr.startswith("error: no Kinema runtime answered within 1 s")
            and done.stderr.count("\n") == 1
        )
        assert time.monotonic() - started < 30
        with pytest.raises(TransportError, match="no Kinema runtime answers"):
            with ObjectiveClient(free_endpoint, timeout=0.5) as client:
                client.execute("Quick")


def test_the_agent_loads_the_robot_model_and_collision_shapes_at_start(lab_sim_agent: Any) -> None:
    """Beside the tick thread, not on the first objective that plans (a mesh robot's first plan waited
    3-4 s for them)."""
    import time

    deadline = time.monotonic() + 30
    while "robot model and collision shapes loaded" not in lab_sim_agent.log_file.read_text():
        assert time.monotonic() < deadline, lab_sim_agent.log_file.read_text()
        time.sleep(0.1)


def test_objective_run_with_a_config_refuses_a_runtime_of_another_one(lab_sim_agent: Any) -> None:
    """`kinema objective run NAME -c CONFIG` on a runtime of another config would move another robot."""

    def run(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [sys.executable, "-m", "kinema", "objective", *args, "--connect", lab_sim_agent.endpoint],
            capture_output=True,
            text=True,
            timeout=60,
        )

    refused = run("run", "Open Gripper", "-c", "panda_cell")
    assert refused.returncode == 1, refused.stdout
    assert (
        "serves config lab_sim, not panda_cell" in refused.stderr
        and "kinema run -c panda_cell" in refused.stderr
    )
    same = run("run", "Hello Tree", "-c", "lab_sim")
    assert same.returncode == 0 and "'Hello Tree' succeeded" in same.stdout, same.stderr
