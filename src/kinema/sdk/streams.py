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

    @property
    def parsed(self) -> Any:
        """The value as Python data: ``42`` → 42, ``[1, 2]`` → [1, 2], a message → a dict.

        A ``std::string`` entry stays the string it holds; text that is not YAML stays text.
        """
        import yaml

        from kinema.nesting import load_yaml

        try:
            data = load_yaml(self.value, "the value")
        except (yaml.YAMLError, ValueError):
            return self.value
        if self.type_name in _STRING_TYPES and not isinstance(data, str):
            return self.value if data is None else str(data)
        return data


@dataclass(frozen=True)
class BlackboardSnapshot:
    """Every blackboard entry of the running (or last) objective.

    Read it like a mapping of the objective's own keys, values parsed into Python data::

        snapshot["sum"]                  # 42 (an int)
        snapshot.value("sum", int)       # 42, typed for mypy (TypeError if it is not an int)
        snapshot.get("missing", 0)       # 0
        snapshot.scope("Add::3")["x"]    # a key of a subtree's own blackboard

    A key is looked up in the objective's root blackboard first, then in the only subtree scope that
    has it; ``scopes`` names every scope.
    """

    objective_name: str
    stamp: float
    entries: tuple[BlackboardValue, ...]

    @property
    def scopes(self) -> list[str]:
        """The scopes (the root's is the objective's name, subtrees are their instance paths)."""
        return list(dict.fromkeys(entry.scope for entry in self.entries))

    def scope(self, name: str) -> dict[str, Any]:
        """``{key: parsed value}`` of one scope.

        Raises:
            KeyError: no such scope (the message lists them).
        """
        if name not in self.scopes:
            raise KeyError(f"no blackboard scope {name!r}; scopes: {', '.join(self.scopes) or 'none'}")
        return {entry.key: entry.parsed for entry in self.entries if entry.scope == name}

    def entry(self, key: str) -> BlackboardValue:
        """The entry ``key`` resolves to (see the class docstring).

        Raises:
            KeyError: no scope has ``key``, or several subtree scopes do and the root does not.
        """
        found = [entry for entry in self.entries if entry.key == key]
        root = [entry for entry in found if entry.scope in (self.objective_name, "")]
        if root:
            return root[0]
        if len(found) == 1:
            return found[0]
        if found:
            scopes = ", ".join(entry.scope for entry in found)
            raise KeyError(f"blackboard key {key!r} is in several scopes ({scopes}); use scope(name)[key]")
        from kinema.errors import did_you_mean

        raise KeyError(f"no blackboard key {key!r}; {did_you_mean(key, self.keys())}")

    def keys(self) -> list[str]:
        """Every key, root scope first."""
        return list(dict.fromkeys(entry.key for entry in sorted(self.entries, key=self._root_first)))

    def _root_first(self, entry: BlackboardValue) -> bool:
        return entry.scope not in (self.objective_name, "")

    def __getitem__(self, key: str) -> Any:
        return self.entry(key).parsed

    def __contains__(self, key: object) -> bool:
        return isinstance(key, str) and any(entry.key == key for entry in self.entries)

    def get(self, key: str, default: Any = None) -> Any:
        """``snapshot[key]``, or ``default`` when no scope has it."""
        try:
            return self[key]
        except KeyError:
            return default

    def value(self, key: str, kind: type[T]) -> T:
        """``snapshot[key]`` checked to be a ``kind`` (an int is accepted where a float is asked).

        Raises:
            KeyError: see :meth:`entry`.
            TypeError: the value is of another type (the message says which).
        """
        data = self[key]
        if kind is float and isinstance(data, int) and not isinstance(data, bool):
            return float(data)  # type: ignore[return-value]
        if not isinstance(data, kind) or (kind is int and isinstance(data, bool)):
            article = "an" if kind.__name__[:1].lower() in "aeiou" else "a"
            raise TypeError(
                f"blackboard key {key!r} holds {data!r} ({self.entry(key).type_name}), "
                f"not {article} {kind.__name__}"
            )
        return data

    @classmethod
    def from_message(cls, message: Any) -> BlackboardSnapshot:
        """Build from ``kinema_msgs/msg/BlackboardSnapshot``."""
        entries = tuple(BlackboardValue(e.scope, e.key, e.type_name, e.value_yaml) for e in message.entries)
        return cls(message.objective_name, _seconds(message.stamp), entries)

    def as_dict(self) -> dict[str, dict[str, str]]:
        """``{scope: {key: text}}``: each value as the runtime rendered it (YAML text). ``snapshot[key]``,
        :meth:`scope` and :meth:`value` give the values parsed into Python types."""
        out: dict[str, dict[str, str]] = {}
        for entry in self.entries:
            out.setdefault(entry.scope, {})[entry.key] = entry.value
        return out


_STRING_TYPES = frozenset({"std::string", "string", "str"})
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


@dataclass(frozen=True, slots=True)
class NodeStatusChange:
    """One node of a running objective's tree changed status.

    Attributes:
        stamp: the server's clock at the start of the root tick the change happened in (seconds).
        objective_name: the objective whose tree it is.
        uid: the node's uid (depth-first order, 1-based as in BT.CPP).
        node_path: its path from the root, e.g. ``"Pick/TopLevelSequence/MoveToWaypoint"``.
        node_id, node_name: its registration ID (Sequence, MoveToWaypoint, ...) and instance name.
        previous_status, status: IDLE=0, RUNNING=1, SUCCESS=2, FAILURE=3, SKIPPED=4.
    """

    stamp: float
    objective_name: str
    uid: int
    node_path: str
    node_id: str
    node_name: str
    previous_status: int
    status: int


@dataclass(frozen=True, slots=True)
class NodeStatusChanges:
    """Node status changes of one objective, oldest first (usually those of one tick)."""

    objective_name: str
    changes: tuple[NodeStatusChange, ...]


class NodeStatusDecoder:
    """Names the changes of ``/objective_server/node_status`` with their run's node table.

    The server sends a change as one integer (``node index * 25 + previous * 5 + status``) and each
    run's node table once, latched, on ``/objective_server/node_table``. Feed both topics' messages
    here (any thread); changes that arrive before their table wait for it (the newest 256 messages).
    """

    KEEP_TABLES = 8
    KEEP_WAITING = 256

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._tables: dict[int, tuple[str, list[int], list[str], list[str], list[str]]] = {}
        self._waiting: list[Any] = []

    def on_table(self, message: Any) -> list[NodeStatusChanges]:
        """Take a node table; returns the waiting changes it names."""
        table = (
            str(message.objective_name),
            [int(uid) for uid in message.uids],
            [str(path) for path in message.node_paths],
            [str(node_id) for node_id in message.node_ids],
            [str(name) for name in message.node_names],
        )
        with self._lock:
            self._tables[int(message.table_id)] = table
            while len(self._tables) > self.KEEP_TABLES:
                del self._tables[next(iter(self._tables))]
            # Split by table id (messages hold arrays: they cannot be compared with ==).
            ready: list[Any] = []
            still: list[Any] = []
            for waiting in self._waiting:
                (ready if int(waiting.table_id) == int(message.table_id) else still).append(waiting)
            self._waiting = still
        return [self._decode(waiting, table) for waiting in ready]

    @property
    def waiting(self) -> int:
        """How many messages wait for their table."""
        with self._lock:
            return len(self._waiting)

    def on_codes(self, message: Any) -> NodeStatusChanges | None:
        """Take a node status message; None while its table has not arrived (it waits)."""
        with self._lock:
            table = self._tables.get(int(message.table_id))
            if table is None:
                self._waiting.append(message)
                del self._waiting[: -self.KEEP_WAITING]
                return None
        return self._decode(message, table)

    @staticmethod
    def _decode(
        message: Any, table: tuple[str, list[int], list[str], list[str], list[str]]
    ) -> NodeStatusChanges:
        objective, uids, paths, node_ids, names = table
        codes = [int(code) for code in message.codes]
        starts = [int(start) for start in message.starts]
        stamps = [_seconds(stamp) for stamp in message.stamps]
        bounds = [*starts[1:], len(codes)]
        changes = []
        for stamp, first, end in zip(stamps, starts, bounds, strict=True):
            for code in codes[first:end]:
                index = code // 25
                if index >= len(uids):
                    continue  # not of this table: a damaged message
                changes.append(
                    NodeStatusChange(
                        stamp,
                        objective,
                        uids[index],
                        paths[index],
                        node_ids[index],
                        names[index],
                        code // 5 % 5,
                        code % 5,
                    )
                )
        return NodeStatusChanges(str(message.objective_name) or objective, tuple(changes))


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
