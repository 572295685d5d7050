"""Publishers and subscriptions on rmw_zenoh keys, with CDR payloads and the 33-byte attachment.

A *latched* publisher (ROS ``transient_local`` durability) keeps its last ``depth`` samples in a zenoh
``AdvancedPublisher`` cache; a latched subscription is an ``AdvancedSubscriber`` that queries the caches
of publishers already there (and of publishers that appear later). This is the mechanism rmw_zenoh uses
for transient local QoS, so a ROS 2 subscriber with that QoS gets the last sample too.
"""

from __future__ import annotations

import itertools
import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import zenoh
from zenoh import ext

from kinema.errors import TransportError
from kinema.interfaces import dds_type_name
from kinema.transport.attachment import Attachment, encode_attachment, new_gid
from kinema.transport.dispatch import channel, dispatch
from kinema.transport.keys import EntityKind, QoS, data_key, entity_token
from kinema.transport.messages import from_dict, type_of

if TYPE_CHECKING:
    from kinema.transport.node import Node

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class MessageInfo:
    """Where a received message came from."""

    key: str
    sequence_number: int
    source_timestamp: int
    publisher_gid: bytes
    size: int


class Entity:
    """Something a node declares on the graph (owns one liveliness token)."""

    kind: EntityKind

    def __init__(
        self, node: Node, name: str, type_name: str, dds_type: str, type_hash: str, qos: QoS
    ) -> None:
        self.node = node
        self.name = name
        self.type_name = type_name
        self.dds_type = dds_type
        self.type_hash = type_hash
        self.qos = qos
        self.gid = new_gid()
        self.entity_id = node.session.next_entity_id()
        session = node.session
        self.key = data_key(session.domain_id, name, dds_type, type_hash)
        self.token_key = entity_token(
            session.domain_id,
            session.zid,
            node.node_id,
            self.entity_id,
            self.kind,
            node.namespace,
            node.name,
            name,
            dds_type,
            type_hash,
            qos,
        )
        self._token: Any = None
        self._closed = False

    def _announce(self) -> None:
        self._token = self.node.session.zenoh.liveliness().declare_token(self.token_key)
        self.node._adopt(self)

    def _undeclare(self) -> None:
        """Release zenoh resources (subclasses add theirs)."""

    def close(self) -> None:
        """Withdraw from the graph and release the zenoh resources; safe to call twice."""
        if self._closed:
            return
        self._closed = True
        try:
            self._undeclare()
        finally:
            if self._token is not None:
                try:
                    self._token.undeclare()
                except Exception:
                    log.debug("token of %s already gone", self.name, exc_info=True)
            self.node._forget(self)

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name} [{self.type_name}]>"


class Publisher(Entity):
    """Publishes messages of one type on one topic. Create with ``Node.create_publisher``."""

    kind = EntityKind.PUBLISHER

    def __init__(self, node: Node, msg_type: str, topic: str, qos: QoS) -> None:
        registry = node.session.registry
        msg_type = registry.message_type(msg_type)
        super().__init__(node, topic, msg_type, dds_type_name(msg_type), registry.type_hash(msg_type), qos)
        self._registry = registry
        self._sequence = itertools.count(1)
        self._lock = threading.Lock()
        congestion = zenoh.CongestionControl.BLOCK if qos.keep_all else zenoh.CongestionControl.DROP
        reliability = zenoh.Reliability.RELIABLE if qos.reliable else zenoh.Reliability.BEST_EFFORT
        session = node.session.zenoh
        self._publisher: Any
        if qos.transient_local:
            self._publisher = ext.declare_advanced_publisher(
                session,
                self.key,
                congestion_control=congestion,
                reliability=reliability,
                cache=ext.CacheConfig(max_samples=max(qos.depth, 1)),
                publisher_detection=True,
            )
        else:
            self._publisher = session.declare_publisher(
                self.key, congestion_control=congestion, reliability=reliability
            )
        self._announce()

    def publish(self, message: Any) -> None:
        """Publish a message object (or a dict of its fields)."""
        if isinstance(message, dict):
            message = from_dict(self.type_name, message)
        elif type_of(message) != self.type_name:
            raise TransportError(f"publisher on {self.name} sends {self.type_name}, got {type_of(message)}")
        self.publish_raw(self._registry.serialize(message, self.type_name))

    def publish_raw(self, payload: bytes) -> None:
        """Publish an already serialised CDR payload."""
        if self._closed:
            raise TransportError(f"publisher on {self.name} is closed")
        with self._lock:
            attachment = encode_attachment(next(self._sequence), self.gid)
            self._publisher.put(payload, attachment=attachment)

    def subscription_count(self) -> int:
        """Subscriptions currently matching this topic on the graph."""
        return len(self.node.session.graph_cache().snapshot().subscriptions(self.name))

    def _undeclare(self) -> None:
        self._publisher.undeclare()


class Subscription(Entity):
    """Calls ``callback(message)`` for each message on a topic. Create with ``Node.create_subscription``.

    The callback runs on a zenoh thread owned by this subscription (calls are serialised); it must not
    block for long. Exceptions it raises are logged with the topic name, never silently dropped.
    """

    kind = EntityKind.SUBSCRIPTION

    def __init__(
        self,
        node: Node,
        msg_type: str,
        topic: str,
        callback: Callable[..., Any],
        qos: QoS,
        *,
        raw: bool = False,
        with_info: bool = False,
    ) -> None:
        registry = node.session.registry
        msg_type = registry.message_type(msg_type)
        super().__init__(node, topic, msg_type, dds_type_name(msg_type), registry.type_hash(msg_type), qos)
        self._registry = registry
        self._callback = callback
        self._raw = raw
        self._with_info = with_info
        self.received = 0
        session = node.session.zenoh
        self._subscriber: Any
        if qos.transient_local:
            self._subscriber = ext.declare_advanced_subscriber(
                session,
                self.key,
                channel(),
                history=ext.HistoryConfig(detect_late_publishers=True, max_samples=max(qos.depth, 1)),
            )
        else:
            self._subscriber = session.declare_subscriber(self.key, channel())
        node.session._track_dispatcher(dispatch(self._subscriber, self._on_sample, f"-sub{topic}"))
        self._announce()

    def _on_sample(self, sample: Any) -> None:
        try:
            payload = sample.payload.to_bytes()
            self.received += 1
            message: Any = payload if self._raw else self._registry.deserialize(payload, self.type_name)
            if self._with_info:
                try:
                    attachment = Attachment.decode(
                        sample.attachment.to_bytes() if sample.attachment else None
                    )
                except TransportError:
                    attachment = Attachment(0, 0)
                info = MessageInfo(
                    str(sample.key_expr),
                    attachment.sequence_number,
                    attachment.source_timestamp,
                    attachment.gid,
                    len(payload),
                )
                self._callback(message, info)
            else:
                self._callback(message)
        except Exception:
            log.exception("subscription callback on %s [%s] failed", self.name, self.type_name)

    def publisher_count(self) -> int:
        """Publishers currently on this topic on the graph."""
        return len(self.node.session.graph_cache().snapshot().publishers(self.name))

    def _undeclare(self) -> None:
        self._subscriber.undeclare()
