"""Actions: feedback and result, cancel, rejection, handler failures, status updates."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
import time
import uuid
from collections.abc import Callable
from typing import Any

import pytest

from kinema.errors import TransportError
from kinema.transport import (
    STATUS_ABORTED,
    STATUS_CANCELED,
    STATUS_EXECUTING,
    STATUS_SUCCEEDED,
    Node,
    ServerGoalHandle,
    Session,
)
from kinema.transport import action as action_module
from kinema.transport.action import STATUS_UNKNOWN
from kinema.transport.goal_status_cdr import CDR_LE_HEADER

FIB = "example_interfaces/action/Fibonacci"


def _fibonacci(handle: ServerGoalHandle) -> dict[str, list[int]]:
    sequence = [0, 1]
    for _ in range(max(handle.goal.order - 2, 0)):
        sequence.append(sequence[-1] + sequence[-2])
        handle.publish_feedback({"sequence": sequence})
    return {"sequence": sequence[: handle.goal.order]}


def _client(connect: Callable[[], Session], name: str) -> Any:
    client = Node(connect(), "client").create_action_client(FIB, name)
    assert client.wait_for_server(5)
    return client


def test_goal_succeeds_with_feedback_and_result(connect: Callable[[], Session]) -> None:
    Node(connect(), "server").create_action_server(FIB, "/fibonacci", _fibonacci)
    feedback: list[list[int]] = []
    handle = _client(connect, "/fibonacci").send_goal(
        {"order": 6}, lambda f: feedback.append(f.sequence.tolist())
    )
    assert handle.accepted
    outcome = handle.result(timeout=5)
    assert outcome.status == STATUS_SUCCEEDED and outcome.succeeded
    assert outcome.result.sequence.tolist() == [0, 1, 1, 2, 3, 5]
    # Feedback comes on a topic of its own and may be dispatched after the result: it still arrives.
    deadline = time.monotonic() + 5
    while (not feedback or feedback[-1] != [0, 1, 1, 2, 3, 5]) and time.monotonic() < deadline:
        time.sleep(0.01)
    assert feedback and feedback[-1] == [0, 1, 1, 2, 3, 5], feedback
    assert handle.status == STATUS_SUCCEEDED


def test_cancel_reaches_the_execute_callback(connect: Callable[[], Session]) -> None:
    started = threading.Event()

    def until_canceled(handle: ServerGoalHandle) -> None:
        started.set()
        assert handle.cancel_requested_event.wait(5)
        handle.canceled({"sequence": [7]})

    Node(connect(), "server").create_action_server(FIB, "/slow", until_canceled)
    handle = _client(connect, "/slow").send_goal({"order": 1})
    assert started.wait(5)
    assert handle.cancel(timeout=5)
    outcome = handle.result(timeout=5)
    assert outcome.status == STATUS_CANCELED
    assert outcome.result.sequence.tolist() == [7]


def test_cancel_callback_can_refuse(connect: Callable[[], Session]) -> None:
    release = threading.Event()

    def stubborn(handle: ServerGoalHandle) -> dict[str, list[int]]:
        release.wait(5)
        return {"sequence": [1]}

    Node(connect(), "server").create_action_server(
        FIB, "/stubborn", stubborn, cancel_callback=lambda h: False
    )
    handle = _client(connect, "/stubborn").send_goal({"order": 1})
    assert not handle.cancel(timeout=5)
    release.set()
    assert handle.result(timeout=5).status == STATUS_SUCCEEDED


def test_rejected_goal(connect: Callable[[], Session]) -> None:
    Node(connect(), "server").create_action_server(
        FIB, "/picky", _fibonacci, goal_callback=lambda goal: goal.order < 10
    )
    client = _client(connect, "/picky")
    rejected = client.send_goal({"order": 50})
    assert not rejected.accepted
    with pytest.raises(TransportError, match="rejected"):
        rejected.result(timeout=1)
    assert client.send_goal({"order": 3}).result(timeout=5).succeeded


def test_execute_exception_reaches_the_client_as_an_error(connect: Callable[[], Session]) -> None:
    def broken(handle: ServerGoalHandle) -> None:
        raise RuntimeError("gripper on fire")

    server = Node(connect(), "server").create_action_server(FIB, "/broken", broken)
    handle = _client(connect, "/broken").send_goal({"order": 1})
    with pytest.raises(TransportError, match="RuntimeError: gripper on fire"):
        handle.result(timeout=5)
    assert [goal.status for goal in server.goals()] == [STATUS_ABORTED]


def test_status_topic_follows_the_goal(connect: Callable[[], Session]) -> None:
    statuses: list[list[int]] = []
    release = threading.Event()

    def waits(handle: ServerGoalHandle) -> dict[str, list[int]]:
        release.wait(5)
        return {"sequence": [1]}

    Node(connect(), "server").create_action_server(FIB, "/watched", waits)
    watcher = Node(connect(), "watcher")
    watcher.create_subscription(
        "action_msgs/msg/GoalStatusArray",
        "/watched/_action/status",
        lambda m: statuses.append([s.status for s in m.status_list]),
        latched=True,
    )
    handle = _client(connect, "/watched").send_goal({"order": 1})
    deadline = time.monotonic() + 5
    while [2] not in statuses and time.monotonic() < deadline:
        time.sleep(0.01)
    release.set()
    assert handle.result(timeout=5).succeeded
    deadline = time.monotonic() + 5
    while [4] not in statuses and time.monotonic() < deadline:
        time.sleep(0.01)
    assert [2] in statuses and [4] in statuses  # EXECUTING, then SUCCEEDED


_FOREVER_SERVER = """
import sys, threading
from kinema.transport import Node, open_session
session = open_session(sys.argv[1])
Node(session, "doomed").create_action_server(
    "example_interfaces/action/Fibonacci", "/vanishing", lambda handle: threading.Event().wait(60))
print("ready", flush=True)
threading.Event().wait(60)
"""


def test_killed_server_fails_the_pending_result(connect: Callable[[], Session], router_endpoint: str) -> None:
    server = subprocess.Popen(
        [sys.executable, "-c", _FOREVER_SERVER, router_endpoint], stdout=subprocess.PIPE, text=True
    )
    try:
        assert server.stdout is not None and server.stdout.readline().strip() == "ready"
        # A long request timeout: the server's endpoints leaving the graph end the wait, not the timeout.
        handle = _client(connect, "/vanishing").send_goal({"order": 1}, timeout=120)
        assert handle.accepted
        server.send_signal(signal.SIGKILL)
        with pytest.raises(TransportError, match="went away"):
            handle.result(timeout=30)
    finally:
        server.kill()
        server.wait(10)


def test_closing_the_server_cancels_running_goals(connect: Callable[[], Session]) -> None:
    def until_canceled(handle: ServerGoalHandle) -> None:
        handle.cancel_requested_event.wait(10)

    server_session = connect()
    server = Node(server_session, "server").create_action_server(FIB, "/closing", until_canceled)
    handle = _client(connect, "/closing").send_goal({"order": 1})
    # Close once the client's result request has reached the server: a client that has not asked yet
    # learns that the server went away instead (also right, but not what this test is about).
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline and not any(goal._waiters for goal in server.goals()):
        time.sleep(0.01)
    server_session.close()
    assert handle.result(timeout=10).status == STATUS_CANCELED


def test_a_new_goal_can_preempt_the_running_one(connect: Callable[[], Session]) -> None:
    running: list[ServerGoalHandle] = []
    lock = threading.Lock()

    first_running = threading.Event()

    def one_at_a_time(handle: ServerGoalHandle) -> dict[str, list[int]]:
        with lock:
            for older in running:
                older.request_cancel()
            running.append(handle)
        if handle.goal.order == 1:
            first_running.set()
        # The first goal runs until the second preempts it (30 s bounds a failure only); the second
        # finishes at once.
        if handle.cancel_requested_event.wait(30.0 if handle.goal.order == 1 else 0.0):
            handle.canceled({"sequence": [-7]})
            return {}
        return {"sequence": [handle.goal.order]}

    Node(connect(), "server").create_action_server(FIB, "/preempting", one_at_a_time)
    client = _client(connect, "/preempting")
    first = client.send_goal({"order": 1})
    assert first_running.wait(30), "the first goal never started"
    second = client.send_goal({"order": 2})
    assert first.result(timeout=30).status == STATUS_CANCELED
    outcome = second.result(timeout=30)
    assert outcome.succeeded and outcome.result.sequence.tolist() == [2]


def test_missing_action_server_is_named(connect: Callable[[], Session]) -> None:
    client = Node(connect(), "client").create_action_client(FIB, "/nobody")
    with pytest.raises(TransportError, match="no action server /nobody"):
        client.send_goal({"order": 1}, timeout=0.3)


def test_finished_goals_are_kept_up_to_the_limit(connect: Callable[[], Session]) -> None:
    server = Node(connect(), "server").create_action_server(FIB, "/many", _fibonacci, max_finished_goals=3)
    client = _client(connect, "/many")
    handles = []
    for _ in range(6):
        handles.append(client.send_goal({"order": 2}))
        assert handles[-1].result(timeout=5).succeeded
    server._publish_status()  # pruning happens on each status change
    kept = {goal.goal_id for goal in server.goals()}
    assert kept == {handle.goal_id for handle in handles[-3:]}


def _hand_made_goal(client: Any, goal_id: bytes, order: int) -> Any:
    return client._send_goal.call({"goal_id": {"uuid": list(goal_id)}, "goal": {"order": order}}, timeout=5)


def _result_request(client: Any, goal_id: bytes) -> tuple[int, Any]:
    """A get_result for ``goal_id`` on its way (its replies are read with ``client._get_result._collect``)."""
    return client._get_result._send(CDR_LE_HEADER + goal_id, 10)


def test_a_result_request_that_comes_before_its_goal_gets_the_result(connect: Callable[[], Session]) -> None:
    # A Kinema client asks for the result together with the goal: the server holds the request that
    # arrives first until the goal it names ends.
    Node(connect(), "server").create_action_server(FIB, "/early", _fibonacci)
    client = _client(connect, "/early")
    goal_id = uuid.uuid4().bytes
    early = _result_request(client, goal_id)
    assert _hand_made_goal(client, goal_id, 4).accepted
    response = client._get_result._collect(*early)
    assert response.status == STATUS_SUCCEEDED
    assert response.result.sequence.tolist() == [0, 1, 1, 2]


def test_a_held_result_request_is_answered_unknown_when_its_goal_is_rejected(
    connect: Callable[[], Session],
) -> None:
    Node(connect(), "server").create_action_server(
        FIB, "/refusing", _fibonacci, goal_callback=lambda goal: False
    )
    client = _client(connect, "/refusing")
    goal_id = uuid.uuid4().bytes
    early = _result_request(client, goal_id)
    assert not _hand_made_goal(client, goal_id, 4).accepted
    assert client._get_result._collect(*early).status == STATUS_UNKNOWN


def test_a_result_request_for_a_goal_that_never_comes_is_answered_unknown(
    connect: Callable[[], Session], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(action_module, "EARLY_RESULT_HOLD_S", 0.2)
    Node(connect(), "server").create_action_server(FIB, "/forgotten", _fibonacci)
    client = _client(connect, "/forgotten")
    for _ in range(2):  # the second request finds the expiring thread asleep and wakes it
        response = client._get_result._collect(*_result_request(client, uuid.uuid4().bytes))
        assert response.status == STATUS_UNKNOWN


def test_a_server_that_answers_a_goal_once_still_delivers_its_result(
    connect: Callable[[], Session], monkeypatch: pytest.MonkeyPatch
) -> None:
    # rmw_zenoh ignores the send_goal request's result parameter and answers with the acceptance alone:
    # the client then asks get_result, as rcl does.
    monkeypatch.setattr(action_module, "_asks_result", lambda query, response: False)
    asked: list[bytes] = []
    on_get_result = action_module.ActionServer._on_get_result

    def recording(self: Any, request: Any, responder: Any) -> None:
        asked.append(bytes(request.goal_id.uuid))
        on_get_result(self, request, responder)

    monkeypatch.setattr(action_module.ActionServer, "_on_get_result", recording)
    Node(connect(), "server").create_action_server(FIB, "/rcl_like", _fibonacci)
    handle = _client(connect, "/rcl_like").send_goal({"order": 5})
    assert handle.accepted
    outcome = handle.result(timeout=10)
    assert outcome.succeeded and outcome.result.sequence.tolist() == [0, 1, 1, 2, 3]
    assert asked == [handle.goal_id]


def test_a_kinema_server_answers_the_result_on_the_goal_request(
    connect: Callable[[], Session], monkeypatch: pytest.MonkeyPatch
) -> None:
    asked: list[bytes] = []
    monkeypatch.setattr(
        action_module.ActionServer, "_on_get_result", lambda self, request, responder: asked.append(b"")
    )
    Node(connect(), "server").create_action_server(FIB, "/one_request", _fibonacci)
    outcome = _client(connect, "/one_request").send_goal({"order": 4}).result(timeout=10)
    assert outcome.succeeded and outcome.result.sequence.tolist() == [0, 1, 1, 2]
    assert asked == []  # no get_result request


def test_the_result_is_read_by_the_thread_that_waits_for_it(
    connect: Callable[[], Session], monkeypatch: pytest.MonkeyPatch
) -> None:
    # No transport thread is woken to hand the result over: the caller of result() reads its reply.
    finished_on: list[str] = []
    finish = action_module.ClientGoalHandle._finish

    def recording_finish(self: Any, outcome: Any, error: Any) -> None:
        finished_on.append(threading.current_thread().name)
        finish(self, outcome, error)

    monkeypatch.setattr(action_module.ClientGoalHandle, "_finish", recording_finish)
    Node(connect(), "server").create_action_server(FIB, "/waited", _fibonacci)
    client = _client(connect, "/waited")
    waiter = threading.Thread(
        target=lambda: client.send_goal({"order": 4}).result(), name="the waiting thread"
    )
    waiter.start()
    waiter.join(10)
    assert finished_on == ["the waiting thread"]


def test_a_result_nobody_waits_for_still_ends_the_goal(connect: Callable[[], Session]) -> None:
    Node(connect(), "server").create_action_server(FIB, "/unwatched", _fibonacci)
    client = _client(connect, "/unwatched")
    polled = client.send_goal({"order": 3})
    deadline = time.monotonic() + 10
    while not polled.done():
        assert time.monotonic() < deadline, "done() never turned true"
        time.sleep(0.01)
    assert polled.status == STATUS_SUCCEEDED
    called = threading.Event()
    with_callback = client.send_goal({"order": 3})
    with_callback.add_done_callback(lambda _handle: called.set())
    assert called.wait(10)
    assert with_callback.result(timeout=0.1).result.sequence.tolist() == [0, 1, 1]


def test_a_goal_left_to_run_is_let_go_once_it_ended(connect: Callable[[], Session]) -> None:
    # Nobody waits for the first goal nor reads its status: its result is read when the next goal is
    # sent, and the client forgets it instead of holding it (and its request) until it closes.
    Node(connect(), "server").create_action_server(FIB, "/left", _fibonacci)
    client = _client(connect, "/left")
    left = client.send_goal({"order": 2})
    assert client.send_goal({"order": 3}).result(timeout=10).succeeded
    deadline = time.monotonic() + 10
    while left.goal_id in client._pending:
        assert time.monotonic() < deadline, "the goal left to run was never let go"
        client.send_goal({"order": 1}).result(timeout=10)
    assert left.status == STATUS_SUCCEEDED and client._status_sub is None


def test_a_deferred_goal_is_published_executing_when_its_work_says_so(connect: Callable[[], Session]) -> None:
    # As rclcpp's execute(): a goal that ends at once is published once, ended; one that runs on shows
    # EXECUTING from the moment its work calls execute().
    statuses: list[list[int]] = []
    held: list[ServerGoalHandle] = []

    def hold_or_end(handle: ServerGoalHandle) -> None:
        if handle.goal.order == 0:
            handle.succeed({"sequence": []})
        else:
            held.append(handle)

    Node(connect(), "server").create_action_server(FIB, "/deferred", hold_or_end, deferred=True)
    watcher = Node(connect(), "watcher")
    watcher.create_subscription(
        "action_msgs/msg/GoalStatusArray",
        "/deferred/_action/status",
        lambda m: statuses.append([s.status for s in m.status_list]),
        latched=True,
    )
    client = _client(connect, "/deferred")
    assert client.send_goal({"order": 0}).result(timeout=5).succeeded
    _until(lambda: [4] in statuses, "the ended goal's status")
    assert statuses[-1] == [4] and [2] not in statuses and [1] not in statuses, statuses

    running = client.send_goal({"order": 1})
    _until(lambda: bool(held), "the second goal to reach its work")
    time.sleep(0.2)
    assert statuses[-1] == [4], statuses  # accepted, not yet executing: nothing published
    held[0].execute()
    _until(lambda: statuses[-1] == [4, 2], "EXECUTING")
    _until(lambda: running.status == STATUS_EXECUTING, "the client to see EXECUTING")
    held[0].succeed({"sequence": [0]})
    assert running.result(timeout=5).succeeded
    _until(lambda: statuses[-1] == [4, 4], "SUCCEEDED")


def _until(condition: Callable[[], bool], what: str, timeout: float = 5.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.01)


def test_a_waiting_caller_takes_over_reading_the_result_from_a_look_that_stops(
    connect: Callable[[], Session], monkeypatch: pytest.MonkeyPatch
) -> None:
    # done() (the status topic's thread calls it too) only looks at the replies that arrived; a caller
    # blocked in result() while such a look held the replies must read them once it stops.
    monkeypatch.setattr(action_module.ActionClient, "_on_status", lambda self, payload: None)
    release = threading.Event()

    def waits(handle: ServerGoalHandle) -> dict[str, list[int]]:
        release.wait(5)
        return {"sequence": [0, 1]}

    Node(connect(), "server").create_action_server(FIB, "/looked_at", waits)
    handle = _client(connect, "/looked_at").send_goal({"order": 2})
    with handle._lock:
        handle._early_reader = True  # another thread looks at the replies now
    outcome: list[Any] = []
    waiter = threading.Thread(target=lambda: outcome.append(handle.result(timeout=30)))
    waiter.start()
    time.sleep(0.1)
    with handle._lock:
        handle._early_reader = False  # ...and stops without the result
    release.set()
    waiter.join(10)
    assert outcome and outcome[0].result.sequence.tolist() == [0, 1]
