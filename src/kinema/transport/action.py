"""Actions as rcl builds them: three services and two topics under ``<action>/_action/``.

* ``send_goal`` (``Name_SendGoal``): goal id + goal → accepted + stamp;
* ``cancel_goal`` (``action_msgs/srv/CancelGoal``): cancel one goal, all goals, or all up to a time;
* ``get_result`` (``Name_GetResult``): held open by the server until the goal ends → status + result;
* ``feedback`` (``Name_FeedbackMessage``): goal id + feedback;
* ``status`` (``action_msgs/msg/GoalStatusArray``, transient local): every goal the server knows.

So ``ros2 action send_goal`` against a Kinema action server, and a Kinema client against a ROS 2 action
server on rmw_zenoh, both work.

A Kinema client asks for the result with the goal: its ``send_goal`` request carries the selector parameter
:data:`RESULT_WITH_GOAL`, and a Kinema server answers it twice, the acceptance and then, once the goal ended,
the ``get_result`` response (one request and one round trip for a goal that ends at once). Servers that do
not know the parameter ignore it and answer once (rmw_zenoh); the client then asks ``get_result`` as rcl
does. The replies wait in a channel that the thread which needs the result reads itself (``result()``), so
no other thread is woken for them. A client subscribes to the ``status`` topic when a goal's status is
first read (or it falls back to ``get_result``), not before: a caller that only waits for results is not
woken by the status array that every goal publishes as it ends. A Kinema server also holds a
``get_result`` that comes before its goal until the goal is decided (:data:`EARLY_RESULT_HOLD_S` at
most): what earlier Kinema clients sent.
"""

from __future__ import annotations

import logging
import threading
import time
import uuid
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Generic, NamedTuple

import zenoh

from kinema.errors import NoAnswerError, TransportError
from kinema.interfaces import ActionType
from kinema.interfaces.definition import FeedbackT, GoalT, ResultT
from kinema.transport.goal_status_cdr import (
    CDR_LE_HEADER,
    payload_of_chunks,
    status_chunk,
    statuses_of,
)
from kinema.transport.keys import LATCHED_QOS, QoS, fully_qualified
from kinema.transport.messages import from_dict, type_of
from kinema.transport.pubsub import Publisher, Subscription
from kinema.transport.send_goal_cdr import (
    read_send_goal_request,
    response_reader,
    send_goal_request,
    send_goal_response,
)
from kinema.transport.service import Responder, ServiceClient, ServiceServer

if TYPE_CHECKING:
    from kinema.transport.node import Node

log = logging.getLogger(__name__)

STATUS_UNKNOWN = 0
STATUS_ACCEPTED = 1
STATUS_EXECUTING = 2
STATUS_CANCELING = 3
STATUS_SUCCEEDED = 4
STATUS_CANCELED = 5
STATUS_ABORTED = 6
STATUS_NAMES = {
    STATUS_UNKNOWN: "UNKNOWN",
    STATUS_ACCEPTED: "ACCEPTED",
    STATUS_EXECUTING: "EXECUTING",
    STATUS_CANCELING: "CANCELING",
    STATUS_SUCCEEDED: "SUCCEEDED",
    STATUS_CANCELED: "CANCELED",
    STATUS_ABORTED: "ABORTED",
}
TERMINAL = frozenset({STATUS_SUCCEEDED, STATUS_CANCELED, STATUS_ABORTED})
_ACTIVE = frozenset({STATUS_ACCEPTED, STATUS_EXECUTING, STATUS_CANCELING})

CANCEL_ERROR_NONE = 0
CANCEL_ERROR_REJECTED = 1
CANCEL_ERROR_UNKNOWN_GOAL_ID = 2
CANCEL_ERROR_GOAL_TERMINATED = 3

# A get_result request is held open until the goal ends; this only bounds a lost request.
_RESULT_QUERY_TIMEOUT = 7 * 24 * 3600.0
# Closing a server waits this long for its running goals to end as cancelled, so that clients get that
# result rather than "the server went away".
CLOSE_GRACE_S = 1.0
# ...and then this long for the results of goals that ended on close to leave before the server's
# entities close.
CLOSE_FLUSH_S = 0.25
# Feedback travels on a topic, the result on a service: feedback sent before the result may be
# dispatched after it. A finished goal's feedback callback still gets such feedback for this long.
LATE_FEEDBACK_S = 5.0
# A get_result that comes before its goal (the client asks for both at once, and the two are served on
# different threads) is held this long for the goal's decision, then answered UNKNOWN.
EARLY_RESULT_HOLD_S = 2.0
# The selector parameter of a send_goal request whose client wants the result as a second reply.
RESULT_WITH_GOAL = "kinema_result"
_ZERO_ID = bytes(16)
_CHUNK_SIZE = len(status_chunk(_ZERO_ID, 0, 0, 0))


def _stamp_now() -> dict[str, int]:
    now = time.time_ns()
    return {"sec": now // 1_000_000_000, "nanosec": now % 1_000_000_000}


def _uuid_bytes(message: Any) -> bytes:
    # A numpy uint8 array as deserialised (its buffer), or a list of ints.
    return bytes(message.uuid)


def _uuid_message(registry: Any, goal_id: bytes) -> Any:
    import numpy as np

    return registry.message_class("unique_identifier_msgs/msg/UUID")(
        uuid=np.frombuffer(goal_id, dtype=np.uint8).copy()
    )


def _uuid_dict(goal_id: bytes) -> dict[str, Any]:
    return {"uuid": list(goal_id)}


def _action_names(node: Node, name: str) -> str:
    return fully_qualified(name, node.namespace, node.name)


@dataclass(frozen=True)
class GoalResult(Generic[ResultT]):
    """How a goal ended: its final status (``STATUS_*``) and the result message."""

    status: int
    result: ResultT

    @property
    def status_name(self) -> str:
        """``SUCCEEDED``, ``CANCELED``, ``ABORTED``, ..."""
        return STATUS_NAMES.get(self.status, str(self.status))

    @property
    def succeeded(self) -> bool:
        """True when the goal SUCCEEDED."""
        return self.status == STATUS_SUCCEEDED


class _GoalRequest(NamedTuple):
    """A send_goal request as the server reads it: the goal's UUID (16 bytes) and the goal."""

    goal_id: bytes
    goal: Any


class _Acceptance(NamedTuple):
    """A send_goal response as the server writes it."""

    accepted: bool
    sec: int
    nanosec: int


def _write_acceptance(response: _Acceptance) -> bytes:
    return send_goal_response(response.accepted, response.sec, response.nanosec)


class ServerGoalHandle:
    """One accepted goal on the server side, handed to the execute callback.

    The execute callback reads ``goal``, sends feedback with :meth:`publish_feedback`, polls
    :attr:`is_cancel_requested` (or waits on :attr:`cancel_requested_event`) and ends the goal with
    :meth:`succeed`, :meth:`abort` or :meth:`canceled`. Returning a result without ending the goal
    succeeds it (or cancels it when a cancel was requested).
    """

    def __init__(self, server: ActionServer, goal_id: bytes, goal: Any) -> None:
        self.server = server
        self.goal_id = goal_id
        self.goal = goal
        self.stamp = _stamp_now()
        self.status = STATUS_ACCEPTED
        self.result: Any = None
        self.error: str | None = None
        self.terminated_at: float | None = None
        self.cancel_requested_event = threading.Event()
        self._waiters: list[Responder] = []
        self._lock = threading.Lock()
        self._goal_info: Any = None
        # This goal's element of the status array (goal_status_cdr.status_chunk), and the status it shows.
        self._chunk = b""
        self._chunk_status = -1
        # The get_result response once the goal ended (see _answer).
        self._result_payload: bytes | None = None

    @property
    def goal_info(self) -> Any:
        """The ``action_msgs/msg/GoalInfo`` of this goal (built on first use: feedback, cancel replies)."""
        info = self._goal_info
        if info is None:
            registry = self.server.node.session.registry
            stamp = registry.message_class("builtin_interfaces/msg/Time")(**self.stamp)
            info = registry.message_class("action_msgs/msg/GoalInfo")(
                goal_id=_uuid_message(registry, self.goal_id), stamp=stamp
            )
            self._goal_info = info
        return info

    def _status_chunk(self) -> bytes:
        status = self.status
        if status != self._chunk_status:
            self._chunk = status_chunk(self.goal_id, self.stamp["sec"], self.stamp["nanosec"], status)
            self._chunk_status = status
        return self._chunk

    @property
    def goal_uuid(self) -> uuid.UUID:
        """The goal id as a UUID."""
        return uuid.UUID(bytes=self.goal_id)

    @property
    def is_cancel_requested(self) -> bool:
        """True once a client asked to cancel this goal (and the cancel callback accepted)."""
        return self.cancel_requested_event.is_set()

    @property
    def is_active(self) -> bool:
        """True until the goal succeeds, aborts or is canceled."""
        return self.status in _ACTIVE

    def request_cancel(self) -> bool:
        """Ask this goal to stop from the server side (e.g. a newer goal preempts it).

        Marks the goal CANCELING and sets :attr:`cancel_requested_event`, exactly as a client's cancel
        request would; the execute callback then ends it (usually with :meth:`canceled` or
        :meth:`abort`). Returns False when the goal had already ended.
        """
        if not self.is_active:
            return False
        self.cancel_requested_event.set()
        self._set_status(STATUS_CANCELING)
        return True

    def execute(self) -> None:
        """Mark the goal EXECUTING and publish its status, as rclcpp's ``execute()``.

        A deferred server's goals stay ACCEPTED, unpublished, until the code that runs them calls this:
        a goal that ends first is published once, as it ends (one status message instead of two for a
        goal that ends at once). Does nothing once the goal executes, is being cancelled or ended.
        """
        with self._lock:
            if self.status != STATUS_ACCEPTED:
                return
            self.status = STATUS_EXECUTING
        self.server._publish_status()

    def publish_feedback(self, feedback: Any) -> None:
        """Send feedback (a message or a dict of its fields) to the clients."""
        action = self.server.action
        message = (
            from_dict(action.feedback, feedback)
            if isinstance(feedback, dict) or feedback is None
            else feedback
        )
        feedback_message = self.server._feedback_class(goal_id=self.goal_info.goal_id, feedback=message)
        self.server._feedback.publish(feedback_message)

    def succeed(self, result: Any = None) -> None:
        """End the goal as SUCCEEDED with ``result`` (message, dict, or None for defaults)."""
        self._terminate(STATUS_SUCCEEDED, result)

    def abort(self, result: Any = None) -> None:
        """End the goal as ABORTED."""
        self._terminate(STATUS_ABORTED, result)

    def canceled(self, result: Any = None) -> None:
        """End the goal as CANCELED (after a cancel request)."""
        self._terminate(STATUS_CANCELED, result)

    def _set_status(self, status: int) -> None:
        with self._lock:
            if self.status in TERMINAL or self.status == status:
                return
            self.status = status
        self.server._publish_status()

    def _terminate(self, status: int, result: Any, error: str | None = None) -> None:
        action = self.server.action
        if result is None or isinstance(result, dict):
            result = from_dict(action.result, result)
        elif type_of(result) != action.result:
            raise TransportError(
                f"result of {self.server.name} must be {action.result}, got {type_of(result)}"
            )
        with self._lock:
            if self.status in TERMINAL:
                raise TransportError(
                    f"goal {self.goal_uuid} of {self.server.name} already ended "
                    f"as {STATUS_NAMES[self.status]}"
                )
            self.status = status
            self.result = result
            self.error = error
            self.terminated_at = time.monotonic()
            # An ended goal is kept until it expires only to answer get_result: its request (up
            # to a whole objective's XML) is let go now, so rejected large goals do not pile up.
            self.goal = None
            waiters, self._waiters = self._waiters, []
        self.server._note_terminated(self)
        # The waiting clients first: the status array is for watchers, the result is what a caller waits for.
        for responder in waiters:
            self._answer(responder)
        self.server._publish_status()

    def _add_waiter(self, responder: Responder) -> None:
        with self._lock:
            if self.status not in TERMINAL:
                self._waiters.append(responder)
                return
        self._answer(responder)

    def _answer(self, responder: Responder) -> None:
        server = self.server
        try:
            payload = self._result_payload
            if payload is None:
                # Once per goal, whoever waits (get_result requests, the send_goal that asked for it).
                response = server._get_result_class(status=self.status, result=self.result)
                payload = self._result_payload = server.node.session.registry.serialize(
                    response, server.action.get_result.response
                )
            responder.reply_payload(payload, self.error)
        except Exception:
            log.exception("cannot send the result of goal %s on %s", self.goal_uuid, server.name)


ExecuteCallback = Callable[[ServerGoalHandle], Any]
GoalCallback = Callable[[Any], bool]
CancelCallback = Callable[[ServerGoalHandle], bool]


class ActionServer:
    """Serves one action. Create with ``Node.create_action_server``.

    ``execute_callback(goal_handle)`` runs on its own thread per accepted goal. ``goal_callback(goal)``
    (default: accept all) decides acceptance; ``cancel_callback(goal_handle)`` (default: accept) decides
    whether a cancel request is honoured. An exception in the execute callback aborts the goal; Kinema
    clients then get a TransportError with the message from ``result()``.

    With ``deferred=True`` the execute callback instead runs right after the goal is accepted, on the
    thread that accepted it: it must not block, and ends the goal later, from any thread, with the
    handle's :meth:`~ServerGoalHandle.succeed`, :meth:`~ServerGoalHandle.abort` or
    :meth:`~ServerGoalHandle.canceled` (what it returns is ignored). For work that another thread does
    anyway (the objective server's tick thread): no thread is started per goal. The goal stays ACCEPTED
    until that work calls :meth:`~ServerGoalHandle.execute`.
    """

    def __init__(
        self,
        node: Node,
        action_type: str,
        name: str,
        execute_callback: ExecuteCallback,
        *,
        goal_callback: GoalCallback | None = None,
        cancel_callback: CancelCallback | None = None,
        result_timeout: float = 900.0,
        max_finished_goals: int = 100,
        deferred: bool = False,
    ) -> None:
        self.node = node
        registry = node.session.registry
        self.action: ActionType = registry.action(action_type)
        self.name = _action_names(node, name)
        self.type_name = self.action.name
        self._execute_callback = execute_callback
        self._goal_callback = goal_callback
        self._cancel_callback = cancel_callback
        self._result_timeout = result_timeout
        self._max_finished = max_finished_goals
        self._deferred = deferred
        self._feedback_class = registry.message_class(self.action.feedback_message)
        self._get_result_class = registry.message_class(self.action.get_result.response)
        self._registry = registry
        self._goals: dict[bytes, ServerGoalHandle] = {}
        self._active: dict[bytes, ServerGoalHandle] = {}
        # The ended goals in the order they ended (the status array lists them first, and they expire
        # from the front), and their status elements joined, kept while no goal ends or expires.
        self._finished: dict[bytes, ServerGoalHandle] = {}
        self._finished_chunks: bytes | None = None
        # get_result requests that came before their goal: goal id -> [(deadline, responder)].
        self._early: dict[bytes, list[tuple[float, Responder]]] = {}
        self._early_thread: threading.Thread | None = None
        self._early_idle = False
        self._lock = threading.RLock()
        self._early_wake = threading.Condition(self._lock)
        self._closed = False
        base = f"{self.name}/_action"
        action = self.action
        self._status = Publisher(node, action.status, f"{base}/status", LATCHED_QOS)
        self._feedback = Publisher(node, action.feedback_message, f"{base}/feedback", QoS())
        self._get_result = ServiceServer(
            node, action.get_result, f"{base}/get_result", self._on_get_result, deferred=True
        )
        self._cancel = ServiceServer(node, action.cancel_goal, f"{base}/cancel_goal", self._on_cancel)
        self._send_goal = ServiceServer(
            node,
            action.send_goal,
            f"{base}/send_goal",
            self._on_send_goal,
            after_reply=self._after_send_goal,
            keep_open=_asks_result,
            request_reader=self._read_send_goal,
            response_writer=_write_acceptance,
        )
        self._unknown_payload = registry.serialize(
            from_dict(action.get_result.response, {"status": STATUS_UNKNOWN}), action.get_result.response
        )
        node._adopt(self)
        self._publish_status()

    # -- goals -----------------------------------------------------------------------------------

    def goals(self) -> list[ServerGoalHandle]:
        """Goals the server knows (active, and ended ones not yet expired)."""
        with self._lock:
            return list(self._goals.values())

    def _read_send_goal(self, payload: bytes) -> _GoalRequest:
        """The goal id and goal of a send_goal request: the UUID read where it lies and only the goal
        deserialised (a little-endian request), or the whole request through the generic deserializer."""
        fields = read_send_goal_request(payload)
        if fields is None:
            message = self._registry.deserialize(payload, self.action.send_goal.request)
            return _GoalRequest(_uuid_bytes(message.goal_id), message.goal)
        goal_id, goal_cdr = fields
        return _GoalRequest(goal_id, self._registry.deserialize(goal_cdr, self.action.goal))

    def _on_send_goal(self, request: _GoalRequest) -> _Acceptance:
        goal_id = request.goal_id
        with self._lock:
            duplicate = goal_id in self._goals
        accepted = not duplicate and not self._closed
        if duplicate:
            log.warning("%s: goal id %s is already in use; rejected", self.name, uuid.UUID(bytes=goal_id))
        if accepted and self._goal_callback is not None:
            accepted = bool(self._goal_callback(request.goal))
        handle = None
        early: list[tuple[float, Responder]] = []
        with self._lock:
            if not duplicate:
                early = self._early.pop(goal_id, [])
            if accepted:
                handle = ServerGoalHandle(self, goal_id, request.goal)
                # Result requests that came first wait for this goal's end like any later one.
                handle._waiters.extend(responder for _deadline, responder in early)
                self._goals[goal_id] = handle
                self._active[goal_id] = handle
        if not accepted:
            for _deadline, responder in early:
                _answer_unknown(responder, self._unknown_payload)
        stamp = handle.stamp if handle else _stamp_now()
        return _Acceptance(accepted, stamp["sec"], stamp["nanosec"])

    def _after_send_goal(
        self, request: _GoalRequest, response: _Acceptance, result_responder: Responder | None
    ) -> None:
        if not response.accepted:
            return
        with self._lock:
            handle = self._goals.get(request.goal_id)
        if handle is None:
            if result_responder is not None:
                _answer_unknown(result_responder, self._unknown_payload)
            return
        if result_responder is not None:
            # Its client asked for the result with the goal: answered as it ends, like a get_result.
            handle._add_waiter(result_responder)
        if self._deferred:
            # Its status is published when its work calls execute(), or as it ends.
            self._start_deferred(handle)
            return
        # Accepted and executing from here on: one status message says both.
        with handle._lock:
            if handle.status == STATUS_ACCEPTED:
                handle.status = STATUS_EXECUTING
        self._publish_status()
        thread = threading.Thread(
            target=self._execute, args=(handle,), name=f"kinema-goal{self.name}", daemon=True
        )
        thread.start()

    def _start_deferred(self, handle: ServerGoalHandle) -> None:
        try:
            self._execute_callback(handle)
        except Exception as error:
            log.exception("execute callback of action %s raised", self.name)
            if handle.status not in TERMINAL:
                handle._terminate(
                    STATUS_ABORTED, None, error=f"action {self.name} failed: {type(error).__name__}: {error}"
                )

    def _execute(self, handle: ServerGoalHandle) -> None:
        handle._set_status(STATUS_EXECUTING)
        try:
            outcome = self._execute_callback(handle)
        except Exception as error:
            log.exception("execute callback of action %s raised", self.name)
            if handle.status not in TERMINAL:
                handle._terminate(
                    STATUS_ABORTED, None, error=f"action {self.name} failed: {type(error).__name__}: {error}"
                )
            return
        if handle.status in TERMINAL:
            return
        if outcome is None and not handle.is_cancel_requested:
            log.warning("execute callback of %s returned without ending the goal; aborting it", self.name)
            handle.abort()
        elif handle.is_cancel_requested:
            handle.canceled(outcome)
        else:
            handle.succeed(outcome)

    def _on_get_result(self, request: Any, responder: Responder) -> None:
        goal_id = _uuid_bytes(request.goal_id)
        with self._lock:
            handle = self._goals.get(goal_id)
            if handle is None and not self._closed:
                # Its goal may be on its way (sent just before, served on another thread): hold it.
                self._early.setdefault(goal_id, []).append(
                    (time.monotonic() + EARLY_RESULT_HOLD_S, responder)
                )
                if self._early_thread is None:
                    self._early_thread = threading.Thread(
                        target=self._expire_early, name=f"kinema-early{self.name}", daemon=True
                    )
                    self._early_thread.start()
                elif self._early_idle:
                    self._early_wake.notify()
                return
        if handle is None:
            _answer_unknown(responder, self._unknown_payload)
            return
        handle._add_waiter(responder)

    def _expire_early(self) -> None:
        """Answer UNKNOWN to held result requests whose goal did not come in time.

        One thread, from the first held request until the server closes. It sweeps a few times per hold
        while requests are held (most are claimed by their goal within microseconds) and sleeps
        otherwise.
        """
        while True:
            with self._lock:
                if self._closed:
                    return  # close() answers the requests still held
                now = time.monotonic()
                expired: list[Responder] = []
                for goal_id, waiting in list(self._early.items()):
                    expired += [responder for deadline, responder in waiting if deadline <= now]
                    kept = [(deadline, responder) for deadline, responder in waiting if deadline > now]
                    if kept:
                        self._early[goal_id] = kept
                    else:
                        del self._early[goal_id]
                if not expired:
                    self._early_idle = not self._early
                    self._early_wake.wait(None if self._early_idle else EARLY_RESULT_HOLD_S / 4)
                    self._early_idle = False
                    continue
            for responder in expired:
                _answer_unknown(responder, self._unknown_payload)

    def _on_cancel(self, request: Any) -> Any:
        goal_id = _uuid_bytes(request.goal_info.goal_id)
        stamp = request.goal_info.stamp
        cutoff = stamp.sec * 1_000_000_000 + stamp.nanosec
        with self._lock:
            goals = list(self._goals.values())
        if goal_id != _ZERO_ID:
            selected = [g for g in goals if g.goal_id == goal_id]
            if cutoff:
                selected += [g for g in goals if g.goal_id != goal_id and _ns(g.stamp) <= cutoff]
            if not selected:
                return {"return_code": CANCEL_ERROR_UNKNOWN_GOAL_ID}
        else:
            selected = [g for g in goals if not cutoff or _ns(g.stamp) <= cutoff]
        active = [g for g in selected if g.is_active]
        if selected and not active:
            return {"return_code": CANCEL_ERROR_GOAL_TERMINATED}
        canceling = []
        for handle in active:
            if handle.status == STATUS_CANCELING:
                canceling.append(handle)
                continue
            accept = True
            if self._cancel_callback is not None:
                try:
                    accept = bool(self._cancel_callback(handle))
                except Exception:
                    log.exception("cancel callback of action %s raised; cancel rejected", self.name)
                    accept = False
            if accept:
                handle.cancel_requested_event.set()
                handle._set_status(STATUS_CANCELING)
                canceling.append(handle)
        code = CANCEL_ERROR_NONE if canceling or not active else CANCEL_ERROR_REJECTED
        return {
            "return_code": code,
            "goals_canceling": [g.goal_info for g in canceling],
        }

    def _note_terminated(self, handle: ServerGoalHandle) -> None:
        """Count ``handle`` among the ended goals (before its clients hear of it)."""
        with self._lock:
            if self._active.pop(handle.goal_id, None) is not None:
                self._finished[handle.goal_id] = handle
                if self._finished_chunks is not None:
                    self._finished_chunks += handle._status_chunk()

    def _expire(self, now: float) -> None:
        """Forget ended goals past ``result_timeout``, and the oldest beyond ``max_finished_goals``
        (the lock held), so a burst of goals does not make every status message (and get_result
        lookup) grow forever."""
        finished = self._finished
        while finished:
            goal_id, oldest = next(iter(finished.items()))
            ended = oldest.terminated_at if oldest.terminated_at is not None else now
            if len(finished) <= self._max_finished and now - ended <= self._result_timeout:
                return
            del finished[goal_id]
            self._goals.pop(goal_id, None)
            if self._finished_chunks is not None:
                self._finished_chunks = self._finished_chunks[_CHUNK_SIZE:]

    def _publish_status(self) -> None:
        if self._closed:
            return
        with self._lock:
            self._expire(time.monotonic())
            # Laid out directly (through the generic serializer a full array cost 0.3 ms per change); the
            # ended goals' part is kept, and changes by a chunk when one ends or expires.
            chunks = self._finished_chunks
            if chunks is None:
                chunks = self._finished_chunks = b"".join(h._status_chunk() for h in self._finished.values())
            if self._active:
                chunks += b"".join(h._status_chunk() for h in self._active.values())
            payload = payload_of_chunks(len(self._finished) + len(self._active), chunks)
            try:
                self._status.publish_raw(payload)
            except TransportError:
                log.debug("status publisher of %s closed", self.name)

    def close(self) -> None:
        """Stop serving; running goals are asked to cancel (their threads end on their own)."""
        if self._closed:
            return
        self._closed = True
        with self._lock:
            active = [handle for handle in self._goals.values() if handle.is_active]
        for handle in active:
            handle.cancel_requested_event.set()
        deadline = time.monotonic() + CLOSE_GRACE_S
        while any(handle.is_active for handle in active) and time.monotonic() < deadline:
            time.sleep(0.005)
        with self._lock:
            early = [responder for waiting in self._early.values() for _deadline, responder in waiting]
            self._early.clear()
            self._early_wake.notify_all()
        for responder in early:
            _answer_unknown(responder, self._unknown_payload)
        if active:
            # The results just answered are queued, not delivered (zenoh confirms no reply), and closing
            # the queryable and then the session drops them: the client would hear "went away"
            # instead of CANCELED (4 runs of 6 did). Give them a moment to leave.
            time.sleep(CLOSE_FLUSH_S)
        for entity in (self._send_goal, self._cancel, self._get_result, self._feedback, self._status):
            entity.close()
        self.node._forget(self)

    def __repr__(self) -> str:
        return f"<ActionServer {self.name} [{self.type_name}]>"


def _asks_result(query: Any, response: Any) -> bool:
    """Whether a send_goal request wants the goal's result as a second reply (and its goal was accepted)."""
    return bool(response.accepted) and RESULT_WITH_GOAL in str(query.parameters).split(";")


def _answer_unknown(responder: Responder, payload: bytes) -> None:
    """Answer a get_result for a goal the server does not know (``payload``: that response)."""
    try:
        responder.reply_payload(payload)
    except Exception:
        log.debug("cannot answer a get_result for an unknown goal", exc_info=True)


def _ns(stamp: Any) -> int:
    if isinstance(stamp, dict):
        return int(stamp["sec"]) * 1_000_000_000 + int(stamp["nanosec"])
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


class ClientGoalHandle(Generic[ResultT, FeedbackT]):
    """A goal sent by an :class:`ActionClient`: its status, feedback, cancel and result."""

    def __init__(
        self,
        client: ActionClient[Any, ResultT, FeedbackT],
        goal_id: bytes,
        feedback_callback: Callable[[FeedbackT], Any] | None,
    ) -> None:
        self.client = client
        self.goal_id = goal_id
        self.accepted = False
        self.stamp: Any = None
        self._status = STATUS_UNKNOWN
        self._feedback_callback = feedback_callback
        self._done = threading.Event()
        self._outcome: GoalResult[ResultT] | None = None
        self._error: TransportError | None = None
        self.finished_at: float | None = None
        self._callbacks: list[Callable[[ClientGoalHandle[ResultT, FeedbackT]], Any]] = []
        self._lock = threading.Lock()
        # The result request sent with the goal: whether the goal's acceptance is known, and whether that
        # request ended without the result (the server did not know the goal yet).
        self._decided = False
        self._unanswered = False
        # The replies of the send_goal request after the acceptance (a zenoh channel, the request's
        # sequence number, and when it times out) until they are read, whether a thread reads them now,
        # and what they said so far.
        self._early: tuple[Any, int, float] | None = None
        self._early_reader = False
        self._early_thread = False
        self._early_cancel: Any = None  # a zenoh.CancellationToken: ends the wait (the server went away)
        self._early_response: Any = None
        self._early_errors: list[str] = []

    @property
    def goal_uuid(self) -> uuid.UUID:
        """The goal id as a UUID."""
        return uuid.UUID(bytes=self.goal_id)

    @property
    def status(self) -> int:
        """The latest known status (``STATUS_*``), from the server's status topic while the goal runs.

        The first read of a running goal's status subscribes its client to that topic (latched: the
        server's current statuses come first), so it may still say ACCEPTED for a moment.
        """
        if not self._done.is_set():
            self.client._watch_status()
        return self._status

    @status.setter
    def status(self, status: int) -> None:
        self._status = status

    @property
    def status_name(self) -> str:
        """Name of the latest known status."""
        status = self.status
        return STATUS_NAMES.get(status, str(status))

    def done(self) -> bool:
        """True once the result (or a failure to get it) arrived."""
        if not self._done.is_set():
            self._read_early(block=False)
        return self._done.is_set()

    def add_done_callback(self, callback: Callable[[ClientGoalHandle[ResultT, FeedbackT]], Any]) -> None:
        """Call ``callback(handle)`` when the goal ends (at once if it already has).

        It runs on the thread that received the result (a transport thread, or one waiting in
        :meth:`result`): it must return quickly (hand the work to a loop or an event).
        """
        with self._lock:
            if not self._done.is_set():
                self._callbacks.append(callback)
                waiting = True
            else:
                waiting = False
        if waiting:
            self._read_early_on_thread()
            return
        callback(self)

    def cancel(self, timeout: float = 5.0) -> bool:
        """Ask the server to cancel this goal; True when it accepted (the goal is now CANCELING)."""
        response = self.client._cancel.call(
            {"goal_info": {"goal_id": _uuid_dict(self.goal_id)}}, timeout=timeout
        )
        return any(_uuid_bytes(info.goal_id) == self.goal_id for info in response.goals_canceling)

    def result(self, timeout: float | None = None) -> GoalResult[ResultT]:
        """Wait for the goal to end and return its status and result.

        Raises:
            TransportError: the goal was rejected, the wait timed out, the server's execute callback
                raised (its message), or the server went away.
        """
        if not self.accepted:
            raise TransportError(f"goal {self.goal_uuid} was rejected by {self.client.name}")
        deadline = None if timeout is None else time.monotonic() + timeout
        if not self._done.is_set():
            # The request that asked for the result ends by its timeout: a wait at least that long reads
            # its replies here; a shorter one leaves that to a thread.
            early = self._early
            if early is not None and (deadline is None or deadline >= early[2]):
                self._await_early()
            else:
                self._read_early_on_thread()
        remaining = None if deadline is None else max(0.0, deadline - time.monotonic())
        if not self._done.wait(remaining):
            raise TransportError(
                f"goal {self.goal_uuid} on {self.client.name} did not finish within {timeout:g} s "
                f"(last status {self.status_name})"
            )
        if self._error is not None:
            raise self._error
        assert self._outcome is not None
        return self._outcome

    def _on_feedback(self, feedback: Any) -> None:
        if self._feedback_callback is not None:
            self._feedback_callback(feedback)

    def _decide(self, accepted: bool) -> None:
        """The server answered the goal; ask for the result again if the first request went unanswered."""
        with self._lock:
            self.accepted = accepted
            self._decided = True
            ask = accepted and self._unanswered and not self._done.is_set()
        if ask:
            self.client._wait_result_on_thread(self)

    def _read_early(self, *, block: bool) -> bool:
        """Read the replies of the result request sent with the goal on this thread: until the goal ends
        or the request does (``block``), or only those already there. One thread reads at a time: False
        when another one reads them now (True when read, or nothing is left to read)."""
        with self._lock:
            if self._early is None:
                return True
            if self._early_reader:
                return False
            self._early_reader = True
            replies, sequence, _ends = self._early
        ended = False
        try:
            while not self._done.is_set():
                try:
                    reply = replies.recv() if block else replies.try_recv()
                except zenoh.ZError:  # the request ended: its channel is closed and empty
                    ended = True
                    break
                if reply is None:
                    break
                self._take_early_reply(reply, sequence)
        finally:
            with self._lock:
                self._early_reader = False
                if ended or self._done.is_set():
                    self._early = None
        if ended:
            self._early_request_ended()
        return True

    def _await_early(self) -> None:
        """Read the result request's replies on this thread until the goal or the request ends, taking
        over from another reader that stops (done() only looks at what arrived)."""
        while not self._done.is_set() and not self._read_early(block=True):
            self._done.wait(0.005)

    def _read_early_on_thread(self) -> None:
        """Read the result request's replies on a thread of their own (for done callbacks and short
        waits); one such thread per goal."""
        with self._lock:
            if self._early is None or self._early_thread:
                return
            self._early_thread = True
        threading.Thread(
            target=self._await_early, name=f"kinema-result{self.client.name}", daemon=True
        ).start()

    def _take_early_reply(self, reply: Any, sequence: int) -> None:
        try:
            if reply.ok is not None:
                if self._early_response is not None:
                    return
                response = self.client._get_result._decode_reply(reply.ok, sequence)
                self._early_response = response
                status = int(response.status)
                if status in (STATUS_SUCCEEDED, STATUS_CANCELED):  # only an abort is followed by an error
                    self._finish(GoalResult(status, response.result), None)
            elif reply.err is not None:
                self._early_errors.append(reply.err.payload.to_string())
        except Exception:
            log.exception("%s: the result of goal %s is unreadable", self.client.name, self.goal_uuid)

    def _early_request_ended(self) -> None:
        """The result request sent with the goal ended: finish with what it said, or ask again."""
        try:
            if self._done.is_set():
                return
            errors, response = self._early_errors, self._early_response
            if errors and errors[0] != "Timeout":
                self._finish(None, TransportError(errors[0]))
            elif response is not None and int(response.status) != STATUS_UNKNOWN:
                self._finish(GoalResult(int(response.status), response.result), None)
            else:
                self._early_request_unanswered()
        except Exception:
            log.exception("%s: the result request of goal %s failed", self.client.name, self.goal_uuid)

    def _early_request_unanswered(self) -> None:
        """The result request sent with the goal ended without the result."""
        with self._lock:
            self._unanswered = True
            ask = self._decided and self.accepted and not self._done.is_set()
        if ask:
            self.client._wait_result_on_thread(self)

    def _finish(self, outcome: GoalResult[ResultT] | None, error: TransportError | None) -> None:
        with self._lock:
            if self._done.is_set():
                return
            self._outcome, self._error = outcome, error
            self.finished_at = time.monotonic()
            if outcome is not None:
                self._status = outcome.status
            self._done.set()
            callbacks, self._callbacks = self._callbacks, []
        self.client._ended(self)
        for callback in callbacks:
            try:
                callback(self)
            except Exception:
                log.exception("done callback of goal %s raised", self.goal_uuid)


class ActionClient(Generic[GoalT, ResultT, FeedbackT]):
    """Sends goals to one action. Create with ``Node.create_action_client``; thread-safe.

    Created from a :class:`~kinema.interfaces.definition.ActionDefinition` (``Fibonacci``), it is typed
    with its goal, result and feedback classes; from a type name string, all are ``Any``.
    """

    def __init__(self, node: Node, action_type: str, name: str) -> None:
        self.node = node
        registry = node.session.registry
        self.action: ActionType = registry.action(action_type)
        self.name = _action_names(node, name)
        self.type_name = self.action.name
        # Goals sent, kept LATE_FEEDBACK_S after they end (late feedback still reaches them); those not
        # ended yet (status messages update them); and the ended ones in the order they ended.
        self._handles: dict[bytes, ClientGoalHandle[ResultT, FeedbackT]] = {}
        self._pending: dict[bytes, ClientGoalHandle[ResultT, FeedbackT]] = {}
        self._ended_order: deque[tuple[float, bytes]] = deque()
        self._lock = threading.Lock()
        self._closed = False
        self._read_acceptance = response_reader(registry, self.action.send_goal.response)
        base = f"{self.name}/_action"
        action = self.action
        self._send_goal: ServiceClient[Any, Any] = ServiceClient(node, action.send_goal, f"{base}/send_goal")
        self._cancel: ServiceClient[Any, Any] = ServiceClient(node, action.cancel_goal, f"{base}/cancel_goal")
        self._get_result: ServiceClient[Any, Any] = ServiceClient(
            node, action.get_result, f"{base}/get_result"
        )
        self._feedback_sub = Subscription(
            node, action.feedback_message, f"{base}/feedback", self._on_feedback, QoS()
        )
        # Declared when a goal's status is first read, or when a goal's result is asked with get_result
        # (see _watch_status).
        self._status_sub: Subscription | None = None
        self._status_lock = threading.Lock()
        # A server that dies may never end the request that waits for a goal's result: its endpoints
        # leaving the graph end that wait, and the goal's handle then asks the graph (_wait_result).
        node.session.graph_cache().add_removal_listener(self._on_endpoint_removed)
        node._adopt(self)

    def wait_for_server(self, timeout: float = 5.0) -> bool:
        """Block until the action server's services and topics are all on the graph."""
        name = self.name
        return self.node.session.graph_cache().wait_for(
            lambda graph: graph.action_server_ready(name), timeout
        )

    def send_goal(
        self,
        goal: GoalT | dict[str, Any] | None = None,
        feedback_callback: Callable[[FeedbackT], Any] | None = None,
        *,
        timeout: float = 5.0,
    ) -> ClientGoalHandle[ResultT, FeedbackT]:
        """Send a goal (message, dict of fields, or None for defaults) and return its handle.

        ``feedback_callback(feedback)`` is called on a zenoh thread for each feedback message.
        Check ``handle.accepted``; ``handle.result()`` raises when the goal was rejected.
        """
        return self.send_goal_cdr(self.serialize_goal(goal), feedback_callback, timeout=timeout)

    def serialize_goal(self, goal: GoalT | dict[str, Any] | None) -> bytes:
        """The CDR of a goal (message, dict of fields, or None for defaults), for :meth:`send_goal_cdr`."""
        action = self.action
        goal_msg = from_dict(action.goal, goal) if goal is None or isinstance(goal, dict) else goal
        if type_of(goal_msg) != action.goal:
            raise TransportError(f"goal of {self.name} must be {action.goal}, got {type_of(goal_msg)}")
        return self._send_goal.registry.serialize(goal_msg, action.goal)

    def send_goal_cdr(
        self,
        goal_cdr: bytes,
        feedback_callback: Callable[[FeedbackT], Any] | None = None,
        *,
        timeout: float = 5.0,
    ) -> ClientGoalHandle[ResultT, FeedbackT]:
        """:meth:`send_goal` with the goal already serialised (:meth:`serialize_goal`): a caller that sends
        the same goal again and again serialises it once.

        Raises:
            TransportError: ``goal_cdr`` is not a little-endian CDR payload, or no server answered.
        """
        goal_id = uuid.uuid4().bytes
        try:
            payload = send_goal_request(goal_id, goal_cdr)
        except ValueError as error:
            raise TransportError(f"goal of {self.name}: {error}") from None
        with self._lock:
            self._forget_finished()
            earlier = list(self._pending.values())
        for other in earlier:
            # A result that arrived for a goal nobody waits for or looks at (a goal started and left to
            # run) is read now, so that its handle and its request can go.
            other.done()
        handle = ClientGoalHandle(self, goal_id, feedback_callback)
        with self._lock:
            self._handles[goal_id] = handle
            self._pending[goal_id] = handle
        started = time.monotonic()
        answered_by: list[tuple[int, Any, Any]] = []
        try:
            # The result is asked for with the goal: a goal that ends quickly costs one round trip.
            # The acceptance is the first reply, taken as it comes; the result follows on a Kinema server.
            response = self._send_goal._call_payload(
                payload,
                timeout,
                None,
                started,
                first=True,
                decode=self._read_acceptance,
                parameters=RESULT_WITH_GOAL,
                answered_by=answered_by,
            )
        except TransportError as error:
            self._drop(handle)
            if str(error).startswith("no server for service"):
                raise NoAnswerError(
                    f"no action server {self.name} [{self.type_name}] answered within {timeout:g} s"
                ) from error
            raise
        handle.stamp = response.stamp
        if not response.accepted:
            self._drop(handle)
            return handle
        sequence, replies, cancel = answered_by[0]
        handle._early = (replies, sequence, started + timeout)
        handle._early_cancel = cancel
        if handle._status == STATUS_UNKNOWN:
            handle._status = STATUS_ACCEPTED
        handle._decide(True)
        return handle

    def _drop(self, handle: ClientGoalHandle[ResultT, FeedbackT]) -> None:
        """Forget a goal that was not accepted (rejected, or the server never answered)."""
        handle._decide(False)
        with self._lock:
            self._handles.pop(handle.goal_id, None)
            self._pending.pop(handle.goal_id, None)

    def _watch_status(self) -> None:
        """Subscribe to the server's status topic, once (it is latched: the current statuses come first).

        Never raises: reading a status must not fail (a closing session leaves the last known one)."""
        if self._status_sub is not None:
            return
        with self._status_lock:
            if self._status_sub is not None or self._closed:
                return
            try:
                self._status_sub = Subscription(
                    self.node,
                    self.action.status,
                    f"{self.name}/_action/status",
                    self._on_status,
                    LATCHED_QOS,
                    raw=True,
                )
            except Exception:
                log.debug("%s: cannot subscribe to the goal status topic", self.name, exc_info=True)

    def _wait_result_on_thread(self, handle: ClientGoalHandle[ResultT, FeedbackT]) -> None:
        # The server did not answer the result with the goal (rmw_zenoh): its status topic tells how the
        # goal ended if the server goes away first (_wait_result).
        self._watch_status()
        threading.Thread(
            target=self._wait_result, args=(handle,), name=f"kinema-result{self.name}", daemon=True
        ).start()

    def _wait_result(self, handle: ClientGoalHandle[ResultT, FeedbackT]) -> None:
        request = CDR_LE_HEADER + handle.goal_id  # GetResult_Request: the goal's UUID
        graph = self.node.session.graph_cache()
        missing_since: float | None = None
        while not self._closed and not handle.done():
            try:
                response = self._get_result._call_once(request, _RESULT_QUERY_TIMEOUT)
            except TransportError as error:
                handle._finish(None, error)
                return
            if response is not None:
                handle._finish(GoalResult(int(response.status), response.result), None)
                return
            # No server matched: it may not be discovered yet, or it went away.
            if graph.snapshot().action_server_ready(self.name):
                missing_since = None
            else:
                missing_since = missing_since or time.monotonic()
                if handle.status == STATUS_CANCELED:
                    # The server's last status said so before it closed; a cancelled goal's result
                    # is its empty default.
                    handle._finish(GoalResult(STATUS_CANCELED, from_dict(self.action.result, None)), None)
                    return
                if time.monotonic() - missing_since > 2.0:
                    handle._finish(
                        None,
                        TransportError(
                            f"action server {self.name} went away before goal {handle.goal_uuid} finished"
                        ),
                    )
                    return
            time.sleep(0.02)
        handle._finish(None, TransportError(f"action client {self.name} was closed"))

    def _on_endpoint_removed(self, entity: Any) -> None:
        if not entity.name.startswith(f"{self.name}/_action/"):
            return
        with self._lock:
            waiting = [handle._early_cancel for handle in self._pending.values() if handle._early_cancel]
        if waiting and not self.node.session.graph_cache().snapshot().action_server_ready(self.name):
            for cancel in waiting:
                cancel.cancel()

    def _ended(self, handle: ClientGoalHandle[ResultT, FeedbackT]) -> None:
        with self._lock:
            if self._pending.pop(handle.goal_id, None) is not None and handle.finished_at is not None:
                self._ended_order.append((handle.finished_at, handle.goal_id))

    def _forget_finished(self) -> None:
        """Drop the goals that finished more than LATE_FEEDBACK_S ago (call with the lock held)."""
        now = time.monotonic()
        ended = self._ended_order
        while ended and now - ended[0][0] > LATE_FEEDBACK_S:
            _finished_at, goal_id = ended.popleft()
            self._handles.pop(goal_id, None)

    def _on_feedback(self, message: Any) -> None:
        with self._lock:
            handle = self._handles.get(_uuid_bytes(message.goal_id))
        if handle is not None:
            handle._on_feedback(message.feedback)

    def _on_status(self, payload: bytes) -> None:
        with self._lock:
            if not self._pending:
                return
            pending = dict(self._pending)
        try:
            statuses = statuses_of(payload, pending)
            if statuses is None:  # not little-endian CDR: the generic deserializer reads it
                message = self.node.session.registry.deserialize(payload, self.action.status)
                statuses = {_uuid_bytes(s.goal_info.goal_id): int(s.status) for s in message.status_list}
            for goal_id, status in statuses.items():
                handle = pending.get(goal_id)
                # done() also takes a result that arrived for a goal whose caller has not asked yet.
                if handle is not None and not handle.done():
                    handle._status = status
        except Exception:
            log.warning("%s: unreadable goal status message ignored", self.name, exc_info=True)

    def close(self) -> None:
        """Stop; waiting ``result()`` calls raise TransportError."""
        if self._closed:
            return
        self.node.session.graph_cache().remove_removal_listener(self._on_endpoint_removed)
        with self._status_lock:
            self._closed = True
            status_sub = self._status_sub
        for entity in (self._send_goal, self._cancel, self._get_result, self._feedback_sub, status_sub):
            if entity is not None:
                entity.close()
        with self._lock:
            handles = list(self._handles.values())
        for handle in handles:
            handle._finish(None, TransportError(f"action client {self.name} was closed"))
        self.node._forget(self)

    def __repr__(self) -> str:
        return f"<ActionClient {self.name} [{self.type_name}]>"
