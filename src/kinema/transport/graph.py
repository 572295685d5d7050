"""The ROS graph as seen through rmw_zenoh liveliness tokens: nodes, topics, services, actions.

A :class:`GraphCache` subscribes (with history) to ``@ros2_lv/<domain>/**`` the way an rmw_zenoh context
does, so it knows every entity on the network and learns about new and vanished ones within
milliseconds. :class:`Graph` is an immutable snapshot with the queries ``ros2 node/topic/service/action
list`` answer.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from kinema.transport.dispatch import channel, dispatch
from kinema.transport.keys import LIVELINESS_PREFIX, EntityKind, GraphEntity, parse_token

if TYPE_CHECKING:
    from kinema.transport.session import Session

log = logging.getLogger(__name__)

ACTION_INFIX = "/_action/"
_ACTION_SERVICES = ("send_goal", "cancel_goal", "get_result")
_ACTION_TOPICS = ("feedback", "status")


@dataclass(frozen=True)
class Graph:
    """A snapshot of the graph entities."""

    entities: tuple[GraphEntity, ...]

    def of_kind(self, *kinds: EntityKind) -> list[GraphEntity]:
        """Entities of the given kinds."""
        return [entity for entity in self.entities if entity.kind in kinds]

    def nodes(self) -> list[str]:
        """Fully qualified node names (``/ns/name``), sorted."""
        return sorted({entity.node_fqn for entity in self.of_kind(EntityKind.NODE)})

    def _names_and_types(self, kinds: Iterable[EntityKind], *, hidden: bool) -> dict[str, list[str]]:
        found: dict[str, set[str]] = {}
        for entity in self.of_kind(*kinds):
            if not hidden and ACTION_INFIX in entity.name:
                continue
            found.setdefault(entity.name, set()).add(entity.type_name)
        return {name: sorted(types) for name, types in sorted(found.items())}

    def topics(self, *, hidden: bool = False) -> dict[str, list[str]]:
        """Topic name → type names (publishers and subscriptions); action internals only if ``hidden``."""
        return self._names_and_types((EntityKind.PUBLISHER, EntityKind.SUBSCRIPTION), hidden=hidden)

    def services(self, *, hidden: bool = False) -> dict[str, list[str]]:
        """Service name → type names (servers and clients); action internals only if ``hidden``."""
        return self._names_and_types((EntityKind.SERVICE_SERVER, EntityKind.SERVICE_CLIENT), hidden=hidden)

    def service_servers(self, name: str) -> list[GraphEntity]:
        """Servers offering the service ``name``."""
        return [entity for entity in self.of_kind(EntityKind.SERVICE_SERVER) if entity.name == name]

    def publishers(self, name: str) -> list[GraphEntity]:
        """Publishers on the topic ``name``."""
        return [entity for entity in self.of_kind(EntityKind.PUBLISHER) if entity.name == name]

    def subscriptions(self, name: str) -> list[GraphEntity]:
        """Subscriptions to the topic ``name``."""
        return [entity for entity in self.of_kind(EntityKind.SUBSCRIPTION) if entity.name == name]

    def actions(self) -> dict[str, list[str]]:
        """Action name → action type names (from the send_goal service of their servers and clients)."""
        found: dict[str, set[str]] = {}
        for entity in self.of_kind(EntityKind.SERVICE_SERVER, EntityKind.SERVICE_CLIENT):
            base, sep, part = entity.name.rpartition(ACTION_INFIX)
            if sep and part == "send_goal":
                type_name = entity.type_name
                if type_name.endswith("_SendGoal"):
                    type_name = type_name[: -len("_SendGoal")]
                found.setdefault(base, set()).add(type_name)
        return {name: sorted(types) for name, types in sorted(found.items())}

    def action_server_ready(self, name: str) -> bool:
        """True when the action has what rcl requires: its three services and both publishers."""
        services = {e.name for e in self.of_kind(EntityKind.SERVICE_SERVER)}
        publishers = {e.name for e in self.of_kind(EntityKind.PUBLISHER)}
        return all(f"{name}{ACTION_INFIX}{s}" in services for s in _ACTION_SERVICES) and all(
            f"{name}{ACTION_INFIX}{t}" in publishers for t in _ACTION_TOPICS
        )

    def node_entities(self, node_fqn: str) -> list[GraphEntity]:
        """Everything the node ``/ns/name`` declared."""
        return [
            entity
            for entity in self.entities
            if entity.node_fqn == node_fqn and entity.kind != EntityKind.NODE
        ]


class GraphCache:
    """Live set of liveliness tokens of one ROS domain (what rmw_zenoh's graph cache holds)."""

    def __init__(self, session: Session) -> None:
        self._session = session
        self._tokens: dict[str, GraphEntity] = {}
        self._changed = threading.Condition()
        self._on_removed: list[Callable[[GraphEntity], None]] = []
        self._subscriber = session.zenoh.liveliness().declare_subscriber(
            f"{LIVELINESS_PREFIX}/{session.domain_id}/**", channel(), history=True
        )
        session._track_dispatcher(dispatch(self._subscriber, self._on_sample, "-graph"))

    def _on_sample(self, sample: object) -> None:
        import zenoh

        key = str(sample.key_expr)  # type: ignore[attr-defined]
        entity = parse_token(key)
        if entity is None:
            return
        removed = sample.kind == zenoh.SampleKind.DELETE  # type: ignore[attr-defined]
        with self._changed:
            if removed:
                self._tokens.pop(key, None)
            else:
                self._tokens[key] = entity
            self._changed.notify_all()
            listeners = list(self._on_removed) if removed else []
        for listener in listeners:
            try:
                listener(entity)
            except Exception:
                log.exception("a graph listener raised")

    def add_removal_listener(self, listener: Callable[[GraphEntity], None]) -> None:
        """Call ``listener(entity)`` (on the graph's thread: it must not block) when an entity leaves."""
        with self._changed:
            self._on_removed.append(listener)

    def remove_removal_listener(self, listener: Callable[[GraphEntity], None]) -> None:
        """Stop calling ``listener``."""
        with self._changed:
            if listener in self._on_removed:
                self._on_removed.remove(listener)

    def keys(self) -> set[str]:
        """The liveliness keys of the entities known now."""
        with self._changed:
            return set(self._tokens)

    def snapshot(self) -> Graph:
        """The graph as known now."""
        with self._changed:
            return Graph(tuple(self._tokens.values()))

    def wait_for(self, predicate: Callable[[Graph], bool], timeout: float) -> bool:
        """Block until ``predicate(graph)`` holds or ``timeout`` seconds pass; return whether it held."""
        deadline = time.monotonic() + timeout
        with self._changed:
            while True:
                if predicate(Graph(tuple(self._tokens.values()))):
                    return True
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return False
                self._changed.wait(remaining)

    def close(self) -> None:
        """Stop following the graph."""
        try:
            self._subscriber.undeclare()
        except Exception:
            log.debug("graph subscriber already gone", exc_info=True)


def query_graph(session: Session, timeout: float = 2.0) -> Graph:
    """Ask the network for every liveliness token of the session's domain.

    A liveliness query occasionally comes back empty, or without some of a session's tokens, right after
    links change; it is repeated (until ``timeout``) while it lacks this session's own tokens (when it
    has nodes) or a token that the session's live graph (when it keeps one) already knew as it began.
    """
    deadline = time.monotonic() + timeout
    expect_own = session.node_count() > 0
    cache = session.live_graph_cache()
    known = cache.keys() if cache is not None else set()
    while True:
        replies = session.zenoh.liveliness().get(
            f"{LIVELINESS_PREFIX}/{session.domain_id}/**", timeout=max(deadline - time.monotonic(), 0.01)
        )
        entities: dict[str, GraphEntity] = {}
        for reply in replies:
            if reply.ok is None:
                continue
            key = str(reply.ok.key_expr)
            entity = parse_token(key)
            if entity is not None:
                entities[key] = entity
        graph = Graph(tuple(entities.values()))
        complete = (not expect_own or any(entity.zid == session.zid for entity in graph.entities)) and (
            known <= entities.keys()
        )
        if complete or time.monotonic() >= deadline:
            return graph
        time.sleep(0.005)
        if cache is not None:
            known &= cache.keys()  # what left meanwhile is not missing
