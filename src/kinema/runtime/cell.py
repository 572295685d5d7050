"""One runtime per cell: who runs the agent and the drivers on a network, and what to do about a second.

A *cell* is one robot (real or simulated) with one agent commanding it. Two agents, or two drivers,
on one zenoh network would share every topic: two controllers on one robot, ``/joint_states`` doubled,
goals aborted by the other side. So:

* each agent and driver process declares a **presence token** (:mod:`kinema.transport.presence`: a zenoh
  liveliness token, like the ROS graph's), which disappears when the process does;
* ``kinema run`` looks at the network before it starts anything (:func:`check_cell_is_free`) and refuses
  to start a second agent or second drivers, naming the running ones and how to stop or join them
  (``-n`` and ``-o`` start one part of a cell whose other part runs elsewhere, and stay allowed);
* agents and supervisors keep watching (:class:`CellWatch`) and report two agents or two drivers that
  appear anyway (started at the same moment, or by hand), in their logs, the terminal and the UI.

Processes that declare no presence (an older Kinema, a ROS 2 driver) are still seen through the ROS graph:
a node ``/objective_server`` is an agent; a publisher of ``/joint_states`` or a ``/controller_manager``
node is a driver.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any

from kinema.drivers.mujoco.names import CONTROLLER_MANAGER_NODE, JOINT_STATES_TOPIC
from kinema.errors import KinemaError
from kinema.runtime.names import NODE_NAME
from kinema.transport.presence import (
    AGENT,
    DRIVER,
    PRESENCE_PREFIX,
    ROLES,
    Member,
    declare_presence,
    parse_presence,
    presence_key,
    query_presences,
)

if TYPE_CHECKING:
    from kinema.transport import Graph, Session

__all__ = [
    "AGENT",
    "DRIVER",
    "ROLES",
    "CellError",
    "CellWatch",
    "Member",
    "cell_members",
    "check_cell_is_free",
    "conflicts",
    "declare_presence",
    "parse_presence",
    "presence_key",
    "query_presences",
]

log = logging.getLogger(__name__)

# How a process without a presence token (an older Kinema, a ROS 2 driver) shows in the ROS graph.
AGENT_NODE = f"/{NODE_NAME}"
DRIVER_NODE = f"/{CONTROLLER_MANAGER_NODE}"
DRIVER_TOPIC = JOINT_STATES_TOPIC


class CellError(KinemaError):
    """A second agent or second drivers would join a cell that has them."""


def cell_members(graph: Graph, presences: Iterable[Member]) -> dict[str, list[Member]]:
    """Agents and drivers on the network, by role: one entry per process (zenoh session).

    A process with a presence token is described by it; one seen only in the ROS graph by its zenoh id.
    """
    from kinema.transport.keys import EntityKind

    found: dict[str, dict[str, Member]] = {role: {} for role in ROLES}
    for member in presences:
        found[member.role].setdefault(member.zid, member)
    for entity in graph.entities:
        if entity.kind is EntityKind.NODE and entity.node_fqn == AGENT_NODE:
            found[AGENT].setdefault(entity.zid, Member(AGENT, entity.zid))
        elif (entity.kind is EntityKind.NODE and entity.node_fqn == DRIVER_NODE) or (
            entity.kind is EntityKind.PUBLISHER and entity.name == DRIVER_TOPIC
        ):
            # A driver process has several nodes; its presence (if any) already names it.
            if not any(m.zid == entity.zid for m in found[DRIVER].values()):
                found[DRIVER][entity.zid] = Member(DRIVER, entity.zid)
    return {role: sorted(members.values(), key=lambda m: m.zid) for role, members in found.items()}


def check_cell_is_free(
    session: Session, *, agent: bool, drivers: bool, endpoint: str, timeout: float = 1.5
) -> None:
    """Refuse when the network already has the agent or drivers this ``kinema run`` would start.

    Look through a **client** session of the router. A peer that has just joined sees another peer's
    tokens only once its own direct link to that peer is up (zenoh's peers form a full mesh, and the
    router does not relay between them); a driver busy stepping its simulation can take seconds to
    answer the handshake, and a peer's look would miss it. A client is answered from the router's
    tables, which hold every process linked to it.

    Raises:
        CellError: naming what runs (config, pid, host, endpoint) and how to stop it, join it, or run a
            second cell beside it.
    """
    members = _look(session, timeout)
    clashing = [*(members[AGENT] if agent else []), *(members[DRIVER] if drivers else [])]
    if not clashing:
        return
    running = "; ".join(member.describe() for member in [*members[AGENT], *members[DRIVER]])
    parents = sorted({m.parent_pid for m in clashing if m.parent_pid})
    hosts = sorted({m.host for m in clashing if m.host})
    where = f" on {', '.join(hosts)}" if hosts else ""
    stop = f"`kinema down`{where}" + (
        f" (stops kinema run pid {', '.join(map(str, parents))})" if parents else ""
    )
    hints = [
        f"join it: `kinema ui --connect {endpoint}`, `kinema objective run NAME --connect {endpoint}`",
        f"stop it: {stop}, or Ctrl-C in its terminal",
        "run a second cell beside it: `kinema run --connect tcp/127.0.0.1:<another port>`",
    ]
    if agent and drivers and not (members[AGENT] and members[DRIVER]):
        missing = "-n" if members[DRIVER] else "-o"
        part = "the agent" if members[DRIVER] else "the drivers"
        hints.insert(0, f"start only {part}, which is missing: `kinema run {missing} --connect {endpoint}`")
    parts = " and ".join(p for p, wanted in (("an agent", agent), ("drivers", drivers)) if wanted)
    raise CellError(
        f"a Kinema runtime already runs on {endpoint}: {running}. Starting {parts} here would put a second "
        "one on the same topics (two controllers for one robot), so nothing was started.\n  "
        + "\n  ".join(hints)
    )


def _look(session: Session, timeout: float) -> dict[str, list[Member]]:
    """The cell's members as the network answers within ``timeout``.

    Right after a session joins, while its links to the other peers form, a liveliness query can come
    back empty or with part of the graph; the network is asked again until two answers in a row agree
    (an empty network costs ``timeout``).
    """
    import time

    from kinema.transport import query_graph

    deadline = time.monotonic() + timeout
    previous: frozenset[Any] | None = None
    while True:
        graph = query_graph(session, max(deadline - time.monotonic(), 0.05))
        current = frozenset(graph.entities)
        if (current and current == previous) or time.monotonic() >= deadline:
            break
        previous = current
        time.sleep(0.05)
    # Members seen in the graph are described by their presence; ask until every one has answered
    # (a process without a presence, not a Kinema one, costs the rest of the time).
    deadline = max(deadline, time.monotonic() + 1.0)
    while True:
        members = cell_members(graph, query_presences(session, max(deadline - time.monotonic(), 0.2)))
        described = all(m.pid is not None for role in ROLES for m in members[role])
        if described or time.monotonic() >= deadline:
            return members
        time.sleep(0.05)


def conflicts(members: dict[str, list[Member]]) -> list[str]:
    """One message per role that more than one process holds."""
    messages = []
    for role in ROLES:
        holders = members.get(role, [])
        if len(holders) > 1:
            plural = "agents" if role == AGENT else "drivers"
            messages.append(
                f"{len(holders)} {plural} on one network: {'; '.join(m.describe() for m in holders)}. "
                f"They share every topic; stop all but one (`kinema down` on their host), or give each cell "
                "a router of its own (`kinema run --connect tcp/127.0.0.1:<port>`)"
            )
    return messages


class CellWatch:
    """Reports two agents or two drivers on the network, once per new set, until closed.

    Args:
        session: the session to watch from.
        report: called with each conflict message (from the watch thread).
        period: seconds between looks (the graph is cached locally, so a look is cheap).
    """

    def __init__(self, session: Session, report: Callable[[str], None], *, period: float = 1.0) -> None:
        self._session = session
        self._report = report
        self._period = period
        self._stop = threading.Event()
        self._presences: dict[str, Member] = {}
        self._lock = threading.Lock()
        self._reported: set[str] = set()
        from kinema.transport.dispatch import channel, dispatch

        self._subscriber = session.zenoh.liveliness().declare_subscriber(
            f"{PRESENCE_PREFIX}/{session.domain_id}/**", channel(), history=True
        )
        session._track_dispatcher(dispatch(self._subscriber, self._on_sample, "-cell"))
        self._graph = session.graph_cache()
        self._thread = threading.Thread(target=self._run, name="kinema-cell-watch", daemon=True)
        self._thread.start()
        session._register_closer(self)  # closing the session ends the watch

    def _on_sample(self, sample: Any) -> None:
        import zenoh

        key = str(sample.key_expr)
        member = parse_presence(key)
        if member is None:
            return
        with self._lock:
            if sample.kind == zenoh.SampleKind.DELETE:
                self._presences.pop(key, None)
            else:
                self._presences[key] = member

    def check(self) -> list[str]:
        """The conflicts as seen now (also what the watch thread reports)."""
        with self._lock:
            presences = list(self._presences.values())
        return conflicts(cell_members(self._graph.snapshot(), presences))

    def _run(self) -> None:
        previous: set[str] = set()
        while not self._stop.wait(self._period):
            try:
                current = set(self.check())
            except Exception:
                log.debug("cell watch: could not look at the network", exc_info=True)
                continue
            # Reported once it holds for two looks in a row: a process's graph tokens and its presence
            # arrive one after the other, and the first look may see only half of what it is.
            steady = current & previous
            for message in sorted(steady - self._reported):
                self._report(message)
            self._reported = {message for message in self._reported if message in current} | steady
            previous = current

    def close(self) -> None:
        """Stop watching (safe to call twice)."""
        if self._stop.is_set():
            return
        self._stop.set()
        self._session._unregister_closer(self)
        try:
            self._subscriber.undeclare()
        except Exception:
            log.debug("cell watch subscriber already gone", exc_info=True)
        self._thread.join(timeout=2 * self._period + 1)
