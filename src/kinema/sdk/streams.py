"""What the SDK's stream iterators yield: heartbeat statuses, blackboard snapshots, log messages."""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

from kinema.runtime.objective_status import ObjectiveStatus

T = TypeVar("T")


def _seconds(stamp: Any) -> float:
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9


@dataclass(frozen=True)
class ServerStatus:
    """One heartbeat of the objective server.

    Attributes:
        status: Idle, Loading, Running, Success, Failure or Cancelled.
        objective_name: the objective running or last run ("" before the first).
        process_time: the server's wall time (seconds since the epoch).
        ros_time: the server's clock (simulation time when a simulator runs).
    """

    status: ObjectiveStatus
    objective_name: str
    process_time: float
    ros_time: float

    @classmethod
    def from_message(cls, message: Any) -> ServerStatus:
        """Build from ``moveit_studio_agent_msgs/msg/ObjectiveServerStatus``."""
        try:
            status = ObjectiveStatus(message.objective_status)
        except ValueError:
            status = ObjectiveStatus.UNKNOWN
        return cls(
            status,
            message.objective_name,
            _seconds(message.process_timestamp),
            _seconds(message.ros_timestamp),
        )

    def __str__(self) -> str:
        return f"{self.status}" + (f": {self.objective_name}" if self.objective_name else "")


@dataclass(frozen=True)
class BlackboardValue:
    """One blackboard entry as the server renders it (``value`` is YAML flow text)."""

    scope: str
    key: str
    type_name: str
    value: str


@dataclass(frozen=True)
class BlackboardSnapshot:
    """Every blackboard entry of the running (or last) objective."""

    objective_name: str
    stamp: float
    entries: tuple[BlackboardValue, ...]

    @classmethod
    def from_message(cls, message: Any) -> BlackboardSnapshot:
        """Build from ``kinema_msgs/msg/BlackboardSnapshot``."""
        entries = tuple(BlackboardValue(e.scope, e.key, e.type_name, e.value_yaml) for e in message.entries)
        return cls(message.objective_name, _seconds(message.stamp), entries)

    def as_dict(self) -> dict[str, dict[str, str]]:
        """``{scope: {key: value}}``."""
        out: dict[str, dict[str, str]] = {}
        for entry in self.entries:
            out.setdefault(entry.scope, {})[entry.key] = entry.value
        return out


_LEVELS = {1: "error", 2: "warn", 3: "info"}


@dataclass(frozen=True)
class LogEntry:
    """A message published on the server's log stream (behavior toasts, reloads, results)."""

    level: str
    text: str

    @classmethod
    def from_message(cls, message: Any) -> LogEntry:
        """Build from ``moveit_studio_agent_msgs/msg/Log``."""
        return cls(_LEVELS.get(int(message.log_level), "info"), message.message)

    def __str__(self) -> str:
        return f"{self.level.upper():5} {self.text}"


class MessageStream(Generic[T]):
    """An iterator over messages of one subscription; closing it (or leaving a ``for`` loop) unsubscribes.

    Args:
        subscribe: ``subscribe(callback)`` declares the subscription and returns it (with ``close()``).
        convert: turns a message into what the iterator yields.
        timeout: stop iterating when nothing arrives for this long (None: wait forever).
    """

    _END = object()

    def __init__(
        self,
        subscribe: Callable[[Callable[[Any], None]], Any],
        convert: Callable[[Any], T],
        *,
        timeout: float | None = None,
        maxsize: int = 1000,
    ) -> None:
        self._queue: queue.Queue[Any] = queue.Queue(maxsize)
        self._convert = convert
        self._timeout = timeout
        self._closed = threading.Event()
        self._subscription = subscribe(self._push)

    def _push(self, message: Any) -> None:
        if self._closed.is_set():
            return
        try:
            self._queue.put_nowait(message)
        except queue.Full:
            # A consumer that stopped reading must not block the transport: drop the oldest.
            try:
                self._queue.get_nowait()
            except queue.Empty:
                pass
            self._queue.put_nowait(message)

    def __iter__(self) -> Iterator[T]:
        return self

    def __next__(self) -> T:
        if self._closed.is_set() and self._queue.empty():
            raise StopIteration
        try:
            item = self._queue.get(timeout=self._timeout)
        except queue.Empty:
            self.close()
            raise StopIteration from None
        if item is self._END:
            raise StopIteration
        return self._convert(item)

    def close(self) -> None:
        """Unsubscribe; a blocked ``next()`` returns."""
        if self._closed.is_set():
            return
        self._closed.set()
        try:
            self._subscription.close()
        finally:
            try:
                self._queue.put_nowait(self._END)
            except queue.Full:
                pass

    def __enter__(self) -> MessageStream[T]:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:
            pass
