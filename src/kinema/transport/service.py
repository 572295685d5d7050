"""Services on rmw_zenoh: a complete queryable per server, a ``get`` per call.

The client sends the CDR request with an attachment (its sequence number and GID); the server replies
with the CDR response and an attachment echoing that sequence number and GID (rclcpp matches replies by
it). A handler that raises produces an error reply carrying the message, which the Kinema client raises
as :class:`~kinema.errors.TransportError`; it is never silently dropped.
"""

from __future__ import annotations

import concurrent.futures
import itertools
import logging
import queue
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Generic

import zenoh

from kinema.errors import NoAnswerError, TransportError
from kinema.interfaces import ServiceType
from kinema.interfaces.definition import RequestT, ResponseT
from kinema.transport.attachment import GID_SIZE, Attachment, encode_attachment
from kinema.transport.dispatch import channel, dispatch
from kinema.transport.heap import note_message_size
from kinema.transport.keys import SERVICE_QOS, EntityKind
from kinema.transport.messages import from_dict, type_of
from kinema.transport.pubsub import Entity

if TYPE_CHECKING:
    from kinema.transport.node import Node

log = logging.getLogger(__name__)

# How long a client waits between attempts while no server matches (discovery still propagating).
_RETRY_PAUSE = 0.02
# Where a request goes: zenoh's best matching complete queryable, one server. rmw_zenoh's clients ask
# ALL_COMPLETE (every complete server answers, the first reply is taken); the target is the client's
# choice, servers answer either the same way, and one server per request is what a service call
# means (an action goal is never started twice). ALL_COMPLETE also cost 30-45 us more per round trip
# (a raw query with either target, in one run on a 2-core machine: 188-206 against 234-239 us).
QUERY_TARGET = zenoh.QueryTarget.BEST_MATCHING


def _as_message(value: Any, type_name: str, what: str) -> Any:
    if isinstance(value, dict):
        return from_dict(type_name, value)
    if type_of(value) != type_name:
        raise TransportError(f"{what} must be {type_name}, got {type_of(value)}")
    return value


class _QueryTimedOut(TransportError):
    """zenoh ended a query with its "Timeout" error (no reply within the query's own timeout)."""


class _HandlerPool:
    """Up to ``size`` daemon threads running requests; unlike a ThreadPoolExecutor, a handler still
    blocked (say, waiting for an Objective) never keeps the interpreter from exiting."""

    def __init__(self, size: int, name: str) -> None:
        self._jobs: queue.SimpleQueue[tuple[Callable[..., None], tuple[Any, ...]] | None] = (
            queue.SimpleQueue()
        )
        self._threads = [
            threading.Thread(target=self._work, name=f"{name}-{index}", daemon=True) for index in range(size)
        ]
        self._closed = False
        for thread in self._threads:
            thread.start()

    def _work(self) -> None:
        while (job := self._jobs.get()) is not None:
            function, args = job
            try:
                function(*args)
            except Exception:
                log.exception("service handler thread failed")

    def submit(self, function: Callable[..., None], *args: Any) -> None:
        if self._closed:
            raise RuntimeError("pool is shut down")
        self._jobs.put((function, args))

    def shutdown(self) -> None:
        self._closed = True
        for _ in self._threads:
            self._jobs.put(None)


class Responder:
    """Answers one service request, now or later, from any thread (exactly once)."""

    def __init__(self, server: ServiceServer, query: Any, attachment: Attachment | None) -> None:
        self._server = server
        self._query = query
        self._attachment = attachment
        self._lock = threading.Lock()
        self.done = False

    def _finish(self) -> Any:
        with self._lock:
            if self.done:
                raise TransportError(f"request to {self._server.name} was already answered")
            self.done = True
            return self._query

    def _reply_attachment(self) -> bytes | None:
        request = self._attachment
        if request is None:
            return None
        if len(request.gid) == GID_SIZE:
            return encode_attachment(request.sequence_number, request.gid)
        return Attachment(request.sequence_number, gid=request.gid).encode()  # raises, naming the size

    def reply(self, response: Any, *, more: bool = False) -> None:
        """Send the response (a message object or a dict of its fields).

        With ``more`` the request stays open for a later :meth:`reply_payload` (an action goal whose
        client asked for the result with it).
        """
        server = self._server
        try:
            if server._response_writer is not None:
                payload = server._response_writer(response)
            else:
                message = _as_message(response, server.service.response, f"response of {server.name}")
                payload = server.registry.serialize(message, server.service.response)
        except TransportError as error:
            self.error(str(error))
            return
        if more:
            with self._lock:
                if self.done:
                    raise TransportError(f"request to {server.name} was already answered")
                query = self._query
            query.reply(server.key, payload, attachment=self._reply_attachment())
            return
        query = self._finish()
        try:
            query.reply(server.key, payload, attachment=self._reply_attachment())
        finally:
            query.drop()

    def reply_payload(self, payload: bytes, error: str | None = None) -> None:
        """Send an already serialised reply (then ``error`` as an error reply) and end the request."""
        query = self._finish()
        try:
            query.reply(self._server.key, payload, attachment=self._reply_attachment())
            if error:
                query.reply_err(error.encode())
        finally:
            query.drop()

    def error(self, message: str) -> None:
        """Send an error reply; the Kinema client raises TransportError with ``message``."""
        query = self._finish()
        try:
            query.reply_err(message.encode())
        finally:
            query.drop()


Handler = Callable[[Any], Any]
DeferredHandler = Callable[[Any, Responder], None]


class ServiceServer(Entity):
    """Serves one service. Create with ``Node.create_service``.

    ``handler(request) -> response`` runs on this server's zenoh thread (requests are handled one at a
    time) unless ``max_concurrent > 1``, in which case up to that many run at once on worker threads.
    With ``deferred=True`` the handler is ``handler(request, responder)`` and answers later through
    ``responder.reply(...)`` from any thread (used by action servers for ``get_result``).
    ``after_reply(request, response, responder)`` runs once the response is sent; ``responder`` is the
    request's, still open, when ``keep_open(query, response)`` said so (else None).
    ``request_reader(payload)`` and ``response_writer(response)`` stand in for the generic deserializer and
    serializer (a layout read and written directly); the reader raises TransportError on a bad payload.
    """

    kind = EntityKind.SERVICE_SERVER

    def __init__(
        self,
        node: Node,
        service: ServiceType,
        name: str,
        handler: Handler | DeferredHandler,
        *,
        max_concurrent: int = 1,
        deferred: bool = False,
        after_reply: Callable[[Any, Any, Responder | None], None] | None = None,
        keep_open: Callable[[Any, Any], bool] | None = None,
        request_reader: Callable[[bytes], Any] | None = None,
        response_writer: Callable[[Any], bytes] | None = None,
    ) -> None:
        super().__init__(node, name, service.name, service.dds_name, service.type_hash, SERVICE_QOS)
        self.service = service
        self.registry = node.session.registry
        self._handler = handler
        self._deferred = deferred
        self._after_reply = after_reply
        self._keep_open = keep_open
        self._request_reader = request_reader
        self._response_writer = response_writer
        self._pool = _HandlerPool(max_concurrent, f"kinema-srv{name}") if max_concurrent > 1 else None
        self._queryable = node.session.zenoh.declare_queryable(self.key, channel(), complete=True)
        node.session._track_dispatcher(dispatch(self._queryable, self._on_query, f"-srv{name}"))
        self._announce()

    def _on_query(self, query: Any) -> None:
        try:
            raw_attachment = query.attachment.to_bytes() if query.attachment is not None else None
            attachment = Attachment.decode(raw_attachment) if raw_attachment else None
        except TransportError as error:
            log.warning("request to %s has a bad attachment (%s); replying without one", self.name, error)
            attachment = None
        responder = Responder(self, query, attachment)
        if self._pool is not None:
            try:
                self._pool.submit(self._serve, query, responder)
            except RuntimeError:
                responder.error(f"service {self.name} is shutting down")
        else:
            self._serve(query, responder)

    def _serve(self, query: Any, responder: Responder) -> None:
        try:
            payload = query.payload.to_bytes() if query.payload is not None else b""
            note_message_size(len(payload))
            reader = self._request_reader
            if reader is not None:
                request = reader(payload)
            else:
                request = self.registry.deserialize(payload, self.service.request)
        except TransportError as error:
            responder.error(f"service {self.name}: bad request: {error}")
            return
        try:
            if self._deferred:
                self._handler(request, responder)  # type: ignore[call-arg]
                return
            response = self._handler(request)  # type: ignore[call-arg]
        except Exception as error:
            log.exception("handler of service %s [%s] raised", self.name, self.type_name)
            if not responder.done:
                responder.error(f"service {self.name} failed: {type(error).__name__}: {error}")
            return
        if response is None:
            responder.error(f"service {self.name} failed: its handler returned no response")
            return
        keep = self._keep_open is not None and self._keep_open(query, response)
        responder.reply(response, more=keep)
        if self._after_reply is not None:
            try:
                self._after_reply(request, response, responder if keep else None)
            except Exception:
                log.exception("post-reply step of service %s raised", self.name)

    def _undeclare(self) -> None:
        self._queryable.undeclare()
        if self._pool is not None:
            self._pool.shutdown()


class ServiceClient(Entity, Generic[RequestT, ResponseT]):
    """Calls one service. Create with ``Node.create_client``; thread-safe.

    Created from a :class:`~kinema.interfaces.definition.ServiceDefinition` (``AddTwoInts``), it is
    typed with its request and response classes; from a type name string, both are ``Any``.
    """

    kind = EntityKind.SERVICE_CLIENT

    def __init__(self, node: Node, service: ServiceType, name: str) -> None:
        super().__init__(node, name, service.name, service.dds_name, service.type_hash, SERVICE_QOS)
        self.service = service
        self.registry = node.session.registry
        self._sequence = itertools.count(1)
        self._lock = threading.Lock()
        self._pool: concurrent.futures.ThreadPoolExecutor | None = None
        self._announce()

    def wait_for_service(self, timeout: float = 5.0) -> bool:
        """Block until a server for this service (name and type) is on the graph; return whether one is."""
        name, type_name = self.name, self.type_name
        return self.node.session.graph_cache().wait_for(
            lambda graph: any(s.type_name == type_name for s in graph.service_servers(name)), timeout
        )

    def service_is_ready(self) -> bool:
        """True when a server is on the graph now."""
        return self.wait_for_service(0.0)

    def call(self, request: RequestT | dict[str, Any] | None = None, timeout: float = 5.0) -> ResponseT:
        """Send ``request`` (message, dict of fields, or None for defaults) and return the response.

        While no server matches (it may still be starting or being discovered) the call is retried
        until ``timeout``.

        Raises:
            TransportError: no server answered within ``timeout``, or the server replied with an error
                (its message is in the exception).
        """
        if request is None:
            request = {}
        message = _as_message(request, self.service.request, f"request of {self.name}")
        payload = self.registry.serialize(message, self.service.request)
        return self._call_payload(payload, timeout)  # type: ignore[no-any-return]

    def _call_payload(
        self,
        payload: bytes,
        timeout: float,
        sent: tuple[int, Any] | None = None,
        started: float | None = None,
        *,
        first: bool = False,
        decode: Callable[[bytes], Any] | None = None,
        parameters: str = "",
        answered_by: list[tuple[int, Any, Any]] | None = None,
    ) -> Any:
        """:meth:`call` with a serialised request; ``sent`` is a first attempt already on its way
        (``_send``'s result, sent at ``started``). ``first``, ``decode``: see :meth:`_collect`;
        ``parameters``: see :meth:`_send`. The attempt that got the response is appended to
        ``answered_by`` as its sequence number, replies and the ``zenoh.CancellationToken`` that ends its
        wait (its replies may go on)."""
        deadline = (time.monotonic() if started is None else started) + timeout
        cancel: Any = None
        while True:
            remaining = deadline - time.monotonic()
            try:
                if sent is None:
                    token = zenoh.CancellationToken() if answered_by is not None else None
                    sent = self._send(
                        payload, max(remaining, 0.001), parameters=parameters, cancellation_token=token
                    )
                    cancel = token
                attempt = sent
                outcome = self._collect(*sent, first=first, decode=decode)
                sent = None
            except _QueryTimedOut:
                # A server took the request but did not reply in time (or the last slice was too short
                # for a reply to come back): say which.
                if self.service_is_ready():
                    raise NoAnswerError(f"service {self.name} did not answer within {timeout:g} s") from None
                outcome = None
            if outcome is not None:
                if answered_by is not None:
                    answered_by.append((*attempt, cancel))
                return outcome
            if time.monotonic() + _RETRY_PAUSE >= deadline:
                raise NoAnswerError(
                    f"no server for service {self.name} [{self.type_name}] answered within {timeout:g} s"
                    f"{self._mismatch_hint() or self._access_hint()}"
                )
            time.sleep(_RETRY_PAUSE)

    def _mismatch_hint(self) -> str:
        """Explain a server that exists under this name but with another type or definition."""
        name = self.name
        cache = self.node.session.graph_cache()
        cache.wait_for(lambda graph: bool(graph.service_servers(name)), 0.1)
        others = {(s.type_name, s.type_hash) for s in cache.snapshot().service_servers(name)}
        others.discard((self.type_name, self.type_hash))
        if not others:
            return ""
        found = ", ".join(f"{type_name} ({type_hash})" for type_name, type_hash in sorted(others))
        return (
            f"; a server with another type or interface definition is there: {found}, "
            f"this client uses {self.type_name} ({self.type_hash})"
        )

    def _access_hint(self) -> str:
        """Through a TLS router, a request its access rules deny goes unanswered, not refused: say so."""
        if not any(endpoint.startswith("tls/") for endpoint in self.node.session.endpoints):
            return ""
        return (
            "; through a TLS router this may be its access rules: this machine's certificate may not be "
            "granted the service (`kinema security` on the robot lists what each role may do)"
        )

    def _call_once(self, payload: bytes, timeout: float) -> Any | None:
        sequence, replies = self._send(payload, timeout)
        return self._collect(sequence, replies)

    def _next_sequence(self) -> int:
        with self._lock:
            return next(self._sequence)

    def _send(
        self,
        payload: bytes,
        timeout: float,
        handler: Any = None,
        *,
        sequence: int | None = None,
        parameters: str = "",
        cancellation_token: Any = None,
    ) -> tuple[int, Any]:
        """Send one request; returns its sequence number and zenoh's reply handler (``handler`` if given:
        a ``zenoh.handlers.Callback``), without waiting for a reply. ``parameters`` go in the selector
        (``key?parameters``): servers that do not know them ignore them. Cancelling
        ``cancellation_token`` ends the wait for replies (the server is not told)."""
        if self._closed:
            raise TransportError(f"client of {self.name} is closed")
        if sequence is None:
            sequence = self._next_sequence()
        attachment = Attachment(sequence, gid=self.gid).encode()
        replies = self.node.session.zenoh.get(
            f"{self.key}?{parameters}" if parameters else self.key,
            handler,
            target=QUERY_TARGET,
            consolidation=zenoh.ConsolidationMode.NONE,
            payload=payload,
            attachment=attachment,
            timeout=timeout,
            **({} if cancellation_token is None else {"cancellation_token": cancellation_token}),
        )
        return sequence, replies

    def _collect(
        self,
        sequence: int,
        replies: Any,
        *,
        first: bool = False,
        decode: Callable[[bytes], Any] | None = None,
    ) -> Any | None:
        """The response among ``replies`` (None when no server answered); raises an error reply.

        With ``first``, the first response is returned as it comes, without waiting for the query to
        end: for a service whose server never follows a response with an error
        (:meth:`Responder.reply_payload`'s ``error``), such as an action's ``send_goal``. ``decode(payload)``
        reads the response instead of the generic deserializer.
        """
        response: Any = None
        answered = False
        errors: list[str] = []
        for reply in replies:
            if reply.ok is not None:
                if answered:
                    continue
                response = self._decode_reply(reply.ok, sequence, decode)
                answered = True
                if first and not errors:
                    return response
            elif reply.err is not None:
                errors.append(reply.err.payload.to_string())
        if errors:
            message = errors[0]
            if message == "Timeout":
                raise _QueryTimedOut(message)
            raise TransportError(message)
        return response if answered else None

    def _decode_reply(self, sample: Any, sequence: int, decode: Callable[[bytes], Any] | None = None) -> Any:
        """The response in a reply's sample (a reply echoing another sequence number is logged)."""
        if sample.attachment is not None:
            echoed = Attachment.decode(sample.attachment.to_bytes())
            if echoed.sequence_number != sequence:
                log.warning(
                    "reply on %s echoes sequence %d, expected %d", self.name, echoed.sequence_number, sequence
                )
        payload = sample.payload.to_bytes()
        if decode is not None:
            return decode(payload)
        return self.registry.deserialize(payload, self.service.response)

    def call_async(
        self, request: RequestT | dict[str, Any] | None = None, timeout: float = 5.0
    ) -> concurrent.futures.Future[ResponseT]:
        """Like :meth:`call` on a worker thread; the future holds the response or the TransportError."""
        with self._lock:
            if self._pool is None:
                self._pool = concurrent.futures.ThreadPoolExecutor(
                    4, thread_name_prefix=f"kinema-cli{self.name}"
                )
            pool = self._pool
        return pool.submit(self.call, request, timeout)

    def _undeclare(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=False, cancel_futures=True)
