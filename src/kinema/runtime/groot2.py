"""BT.CPP's Groot2 monitoring protocol, served for the running objective so Groot2 can attach.

Groot2 talks to a ``Groot2Publisher`` over ZeroMQ: a REP socket on ``port`` answers requests, a PUB
socket on ``port + 1`` is where BT.CPP announces reached breakpoints. A request is a multipart message
whose first part is a 6-byte header (uint8 protocol = 2, uint8 request type, uint32 request id); the
reply starts with that header followed by the 16-byte id of the tree being served, which changes
whenever a new objective starts (Groot2 then asks for the new tree). The requests served, as BT.CPP
4.8 answers them:

- ``T`` the tree as XML (``WriteTreeToXML`` with ``_uid``/``_fullpath`` and every node model);
- ``S`` 3 bytes per node (uint16 uid, uint8 status; 10 + the previous status for a node reset to IDLE);
- ``B`` + ``"scope;scope"``: msgpack of ``{scope: {key: value}}`` for those blackboard scopes;
- ``r`` + ``start``/``stop`` toggles the transition recording (``start`` replies the epoch time in
  microseconds); ``t`` returns and clears the recorded transitions, 9 bytes each (6 bytes of
  microseconds since the recording started, uint16 uid, uint8 status);
- ``D`` the hooks (always ``[]``), ``A``/``X`` remove or disable them (nothing to do).

Breakpoints and node substitution (``I``/``R``/``U``) are refused with an error reply: they would block
the tick thread, which must stay cancellable (DESIGN invariant 2). Sockets bind to 127.0.0.1 only.

The server reads the tree from its own thread; the tree is only ever mutated by the objective server's
tick thread, which feeds transitions through :meth:`Groot2Server.on_node_status`.
"""

from __future__ import annotations

import logging
import os
import struct
import threading
import time
from collections import deque
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from kinema.bt.btlog import last_per_key, pack_transition_columns
from kinema.errors import KinemaError

if TYPE_CHECKING:
    from kinema.bt.node import TreeNode
    from kinema.bt.status import NodeStatus
    from kinema.bt.tree import Tree
    from kinema.runtime.node_status import NodeStatusBatch
    from kinema.runtime.objective_server import ObjectiveRun
    from kinema.runtime.objective_status import ObjectiveStatus
    from kinema.runtime.result import ObjectiveResult

log = logging.getLogger("kinema.groot2")

PROTOCOL_ID = 2
DEFAULT_PORT = 1667
REQUEST_HEADER_SIZE = 6
# BT.CPP keeps at most this many recorded transitions between two ``t`` requests.
MAX_RECORDED_TRANSITIONS = 1000
_HOOK_REQUESTS = {ord("I"): "hook_insert", ord("R"): "hook_remove", ord("U"): "breakpoint_unlock"}


def new_tree_uuid() -> bytes:
    """16 random bytes shaped as a version-4 UUID (what BT.CPP sends as the tree id)."""
    raw = bytearray(os.urandom(16))
    raw[6] = (raw[6] & 0x4F) | 0x40
    raw[8] = (raw[8] & 0xBF) | 0x80
    return bytes(raw)


def blackboard_value(value: Any) -> Any:
    """A blackboard value as Groot2 shows it: JSON scalars and lists as they are, anything else as text."""
    if value is None or isinstance(value, str | bool | int | float):
        return value
    if isinstance(value, list | tuple) and all(
        v is None or isinstance(v, str | bool | int | float) for v in value
    ):
        return list(value)
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return blackboard_value(value.tolist())
    return str(value)


class _TreeState:
    """What is served about one tree; replaced as a whole when a new objective starts."""

    __slots__ = (
        "offset_array",
        "recording_epoch",
        "scopes",
        "status",
        "status_index",
        "tree",
        "uuid",
        "xml",
        "zero",
    )

    def __init__(self, tree: Tree) -> None:
        from kinema.bt.model_xml import write_tree_to_xml

        self.tree = tree
        self.uuid = new_tree_uuid()
        self.xml = write_tree_to_xml(tree, add_metadata=True, add_builtin_models=True).rstrip("\n")
        self.status = bytearray()
        self.status_index: dict[int, int] = {}
        self.scopes = {(subtree.instance_name or subtree.tree_id): subtree for subtree in tree.subtrees}
        for node in tree.nodes():
            self.status += struct.pack("<H", node.uid & 0xFFFF)
            self.status_index[node.uid] = len(self.status)
            self.status.append(int(node.status))
        # uid -> offset of its status byte (-1: no such node), for batches of changes
        self.offset_array = np.full(max(self.status_index, default=0) + 1, -1, dtype=np.int64)
        for uid, offset in self.status_index.items():
            self.offset_array[uid] = offset
        # Tree-clock time and wall time at one instant, to turn tree-clock stamps into epoch time.
        self.zero = (tree.clock.now(), time.time())
        self.recording_epoch = 0.0

    def epoch(self, timestamp: float) -> float:
        return self.zero[1] + (timestamp - self.zero[0])


class Groot2Server:
    """Serves the Groot2 protocol for whatever tree :meth:`set_tree` was given last.

    Also an objective-server listener: give it to :class:`~kinema.runtime.objective_server.ObjectiveServer`
    and every objective it runs is served, the finished one staying visible until the next starts.

    Args:
        port: the request port; the publisher binds ``port + 1``.
        host: the address to bind (loopback by default: the protocol has no authentication).

    Raises:
        KinemaError: a port is in use or cannot be bound.
    """

    def __init__(self, port: int = DEFAULT_PORT, *, host: str = "127.0.0.1") -> None:
        import zmq

        self.port = port
        self.host = host
        self._lock = threading.Lock()
        self._state: _TreeState | None = None
        self._recording = False
        self._transitions: deque[bytes] = deque(maxlen=MAX_RECORDED_TRANSITIONS)
        self._context = zmq.Context()
        self._server = self._context.socket(zmq.REP)
        self._publisher = self._context.socket(zmq.PUB)
        for socket in (self._server, self._publisher):
            socket.setsockopt(zmq.LINGER, 0)
            socket.setsockopt(zmq.SNDTIMEO, 1000)
        try:
            self._server.bind(f"tcp://{host}:{port}")
            self._publisher.bind(f"tcp://{host}:{port + 1}")
        except zmq.ZMQError as error:
            self._server.close()
            self._publisher.close()
            self._context.term()
            raise KinemaError(
                f"cannot serve Groot2 on {host}:{port} (requests) and {port + 1} (publisher): {error}; "
                "choose other ports with --groot2-port"
            ) from None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="kinema-groot2", daemon=True)
        self._thread.start()

    # -- the tree (tick thread) ----------------------------------------------------------------------

    def set_tree(self, tree: Tree) -> None:
        """Serve ``tree`` from now on (a new tree id tells Groot2 to fetch it)."""
        state = _TreeState(tree)
        with self._lock:
            self._state = state
            self._transitions.clear()
            state.recording_epoch = time.time()

    def transition(self, timestamp: float, uid: int, previous: int, status: int) -> None:
        """A node of the served tree changed status (``timestamp`` on the tree's clock)."""
        with self._lock:
            state = self._state
            if state is None:
                return
            index = state.status_index.get(uid)
            if index is not None:
                state.status[index] = 10 + previous if status == 0 else status
            if self._recording:
                offset = max(0, round((state.epoch(timestamp) - state.recording_epoch) * 1e6))
                offset = min(offset, (1 << 48) - 1)
                self._transitions.append(offset.to_bytes(6, "little") + struct.pack("<HB", uid, status))

    # -- ServerListener ------------------------------------------------------------------------------

    def on_tree_loaded(self, objective_name: str, tree: Tree) -> None:
        self.set_tree(tree)

    def on_node_status(self, objective_name: str, changes: NodeStatusBatch) -> None:
        # Column-wise: a tick of a large tree brings thousands of changes, one Python step each was
        # most of the tick thread's time.
        with self._lock:
            state = self._state
            if state is None:
                return
            times, uids, previous, statuses = changes.columns()
            shown = np.where(statuses == 0, previous + 10, statuses).astype(np.uint8)
            last_uids, last_shown = last_per_key(uids, shown)
            inside = last_uids < len(state.offset_array)  # a uid of another tree is not served
            last_uids, last_shown = last_uids[inside], last_shown[inside]
            offsets = state.offset_array[last_uids]
            known = offsets >= 0
            np.frombuffer(state.status, dtype=np.uint8)[offsets[known]] = last_shown[known]
            if self._recording:
                epoch = state.zero[1] - state.zero[0] - state.recording_epoch
                micros = np.rint((times + epoch) * 1e6)
                packed = pack_transition_columns(micros, uids, statuses)
                self._transitions.extend(packed[at : at + 9] for at in range(0, len(packed), 9))

    def on_status(self, status: ObjectiveStatus, objective_name: str) -> None:
        pass

    def on_blackboard(self, objective_name: str, entries: list[tuple[str, str, str, Any]]) -> None:
        pass

    def on_run_finished(self, run: ObjectiveRun, result: ObjectiveResult) -> None:
        # A run that ends on an exception may end without its halt having been reported: show what
        # the tree shows now, as Groot2 would see it from BT.CPP (IDLE after the status it had).
        with self._lock:
            state = self._state
        if state is None:
            return
        now = state.tree.clock.now()
        for node in state.tree.nodes():
            index = state.status_index.get(node.uid)
            if index is None:
                continue
            shown = state.status[index]
            active = shown - 10 if shown >= 10 else shown
            status = int(node.status)
            if status != active:
                self.transition(now, node.uid, active, status)

    # -- requests (server thread) --------------------------------------------------------------------

    def _serve(self) -> None:
        import zmq

        poller = zmq.Poller()
        poller.register(self._server, zmq.POLLIN)
        while not self._stop.is_set():
            try:
                if not poller.poll(100):
                    continue
                request = self._server.recv_multipart()
            except zmq.ZMQError:
                if self._stop.is_set():
                    return
                log.exception("Groot2 request socket failed")
                return
            try:
                reply = self.reply(request)
            except Exception as error:
                log.exception("answering a Groot2 request failed")
                reply = [b"error", f"{type(error).__name__}: {error}".encode()]
            try:
                self._server.send_multipart(reply)
            except zmq.ZMQError:
                log.warning("could not send a reply to Groot2 (client gone?)")

    def reply(self, request: Sequence[bytes]) -> list[bytes]:
        """The reply to one request, as a list of message parts (exposed for tests)."""
        if not request or len(request[0]) != REQUEST_HEADER_SIZE:
            return [b"error", b"wrong request header"]
        header = request[0]
        kind = header[1]
        with self._lock:
            state = self._state
        if state is None:
            return [b"error", b"no objective has run yet: start one and ask again"]
        reply_header = bytes([PROTOCOL_ID, kind]) + header[2:6] + state.uuid
        parts = [reply_header]
        if kind == ord("T"):
            parts.append(state.xml.encode("utf-8"))
        elif kind == ord("S"):
            with self._lock:
                parts.append(bytes(state.status))
        elif kind == ord("B"):
            if len(request) != 2:
                return [b"error", b"must be 2 parts message"]
            parts.append(self._blackboard_dump(state, request[1].decode("utf-8", "replace")))
        elif kind in _HOOK_REQUESTS:
            return [b"error", f"{_HOOK_REQUESTS[kind]}: breakpoints are not supported by Kinema".encode()]
        elif kind == ord("D"):
            parts.append(b"[]")
        elif kind in (ord("A"), ord("X")):
            pass
        elif kind == ord("r"):
            if len(request) != 2:
                return [b"error", b"must be 2 parts message"]
            command = request[1]
            if command == b"start":
                now = time.time()
                with self._lock:
                    self._recording = True
                    state.recording_epoch = now
                    self._transitions.clear()
                parts.append(str(int(now * 1e6)).encode())
            elif command == b"stop":
                with self._lock:
                    self._recording = False
        elif kind == ord("t"):
            with self._lock:
                data = b"".join(self._transitions)
                self._transitions.clear()
            parts.append(data)
        else:
            return [b"error", b"Request not recognized"]
        return parts

    def _blackboard_dump(self, state: _TreeState, names: str) -> bytes:
        import msgpack

        dump: dict[str, Any] = {}
        for name in sorted(n for n in names.split(";") if n):
            subtree = state.scopes.get(name)
            if subtree is None:
                continue
            entries = _read_entries(subtree.blackboard)
            dump[name] = {key: blackboard_value(value) for key, value in sorted(entries)} or None
        return msgpack.packb(dump or None)

    # -- lifecycle -----------------------------------------------------------------------------------

    def close(self) -> None:
        """Stop serving and release the ports."""
        if self._stop.is_set():
            return
        self._stop.set()
        self._thread.join(2.0)
        self._server.close()
        self._publisher.close()
        self._context.term()

    def __enter__(self) -> Groot2Server:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _read_entries(blackboard: Any) -> list[tuple[str, Any]]:
    # The tick thread may add an entry while this thread copies: copy again (a few tries suffice).
    for _ in range(5):
        try:
            return [(key, entry.value) for key, entry in list(blackboard.local_entries())]
        except RuntimeError:
            continue
    return []


class Groot2Publisher:
    """BT.CPP's ``Groot2Publisher(tree, port)`` for a tree you tick yourself.

    Observes ``tree`` directly; the runtime serves objective runs with :class:`Groot2Server` as a
    listener of the objective server instead.
    """

    def __init__(self, tree: Tree, port: int = DEFAULT_PORT, *, host: str = "127.0.0.1") -> None:
        self.server = Groot2Server(port, host=host)
        self.server.set_tree(tree)
        self._tree = tree
        self._handle: int | None = tree.add_status_observer(self._on_status)

    def _on_status(self, timestamp: float, node: TreeNode, previous: NodeStatus, status: NodeStatus) -> None:
        self.server.transition(timestamp, node.uid, int(previous), int(status))

    def close(self) -> None:
        """Stop observing the tree and serving."""
        if self._handle is not None:
            self._tree.remove_status_observer(self._handle)
            self._handle = None
        self.server.close()

    def __enter__(self) -> Groot2Publisher:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def transitions_from_bytes(data: bytes) -> list[tuple[int, int, int]]:
    """``(offset_us, uid, status)`` of a ``t`` reply (9 bytes each)."""
    out = []
    for at in range(0, len(data) - len(data) % 9, 9):
        uid, status = struct.unpack_from("<HB", data, at + 6)
        out.append((int.from_bytes(data[at : at + 6], "little"), uid, status))
    return out
