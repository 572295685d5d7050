"""What a behavior reaches the world through: transport node, clock, robot model, log sink.

One :class:`BehaviorContext` is shared by every behavior of a tree (MoveIt Pro's
``BehaviorContext``/"shared resources"). The runtime builds it once with its transport node, the
runtime clock (sim time in simulation) and the robot model provider, and passes it to
:meth:`kinema.plugins.BehaviorRegistry.create_factory`.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, overload

from kinema.behaviors.logger import BehaviorLogger, LogSink
from kinema.errors import ObjectiveError

if TYPE_CHECKING:
    from kinema.bt import Clock
    from kinema.config.cell import CellSettings
    from kinema.interfaces.definition import (
        ActionDefinition,
        FeedbackT,
        GoalT,
        RequestT,
        ResponseT,
        ResultT,
        ServiceDefinition,
    )
    from kinema.transport import ActionClient, QoS, ServiceClient


_UNSET = object()


class BehaviorContext:
    """Resources shared by all behaviors of a tree.

    Args:
        node: the transport node behaviors use for topics, services and actions; None offline
            (building and validating trees, unit tests of behaviors that need no transport).
        clock: the time source (wall time on hardware, sim time in simulation); default wall time.
        log_sink: where ``publish_info/warn/failure`` messages go; a new private sink by default.
        robot_model: a robot model object, or a zero-argument callable that builds it on first use
            (so a behavior that never asks for it never pays for loading it).
        config: the resolved config package the runtime runs (``kinema.config.ResolvedConfig``), for
            behaviors that need its files (the MuJoCo scene as planning scene, say); None without one.
    """

    def __init__(
        self,
        node: Any = None,
        *,
        clock: Clock | None = None,
        log_sink: LogSink | None = None,
        robot_model: Any = None,
        config: Any = None,
    ) -> None:
        if clock is None:
            from kinema.bt import WallClock

            clock = WallClock()
        self.node = node
        self.config = config
        self.clock = clock
        self.log_sink = log_sink if log_sink is not None else LogSink()
        self._robot_model = robot_model
        self._cell: Any = _UNSET
        self._robot_model_lock = threading.Lock()
        self._endpoints: dict[tuple[Any, ...], Any] = {}
        self._endpoints_lock = threading.Lock()

    @property
    def cell(self) -> CellSettings | None:
        """The cell's robot settings (planning group, tool frame, gripper, ...) from the config; None
        without a config. Read once, on first use.

        Raises:
            ConfigError: the config's robot settings are wrong (the message names config.yaml's line).
        """
        if self._cell is _UNSET:
            from kinema.config.cell import CellSettings

            self._cell = CellSettings.from_config(self.config) if self.config is not None else None
        return self._cell  # type: ignore[return-value]

    @classmethod
    def offline(cls) -> BehaviorContext:
        """A context with no transport node: enough to build, validate and unit-test trees."""
        return cls()

    @property
    def robot_model(self) -> Any:
        """The robot model (built on first access when a provider callable was given); None if unset."""
        with self._robot_model_lock:
            if callable(self._robot_model) and not isinstance(self._robot_model, type):
                self._robot_model = self._robot_model()
            return self._robot_model

    def set_robot_model(self, model_or_provider: Any) -> None:
        """Set the robot model, or a zero-argument callable that builds it on first use."""
        with self._robot_model_lock:
            self._robot_model = model_or_provider

    def require_node(self, behavior: str = "") -> Any:
        """Return the transport node, or raise a clear error when this context has none.

        Raises:
            ObjectiveError: the context is offline.
        """
        if self.node is None:
            who = f"behavior '{behavior}' " if behavior else "this behavior "
            raise ObjectiveError(
                f"{who}needs the transport, but it runs without a transport node (offline context); "
                "run it inside `kinema run`, or give BehaviorContext a node in tests"
            )
        return self.node

    @overload
    def service_client(
        self, node: Any, service_type: type[ServiceDefinition[RequestT, ResponseT]], name: str
    ) -> ServiceClient[RequestT, ResponseT]: ...

    @overload
    def service_client(self, node: Any, service_type: str, name: str) -> ServiceClient[Any, Any]: ...

    def service_client(self, node: Any, service_type: Any, name: str) -> ServiceClient[Any, Any]:
        """A service client shared by every behavior of this context (created on first use).

        ``service_type`` is ``pkg/srv/Name`` or a definition class from ``kinema.interfaces.typed``
        (typed responses).
        """
        from kinema.interfaces.definition import interface_type_name

        type_name = interface_type_name(service_type, "srv")
        return self._endpoint(  # type: ignore[no-any-return]
            ("client", id(node), type_name, name), lambda: node.create_client(type_name, name)
        )

    @overload
    def action_client(
        self, node: Any, action_type: type[ActionDefinition[GoalT, ResultT, FeedbackT]], name: str
    ) -> ActionClient[GoalT, ResultT, FeedbackT]: ...

    @overload
    def action_client(self, node: Any, action_type: str, name: str) -> ActionClient[Any, Any, Any]: ...

    def action_client(self, node: Any, action_type: Any, name: str) -> ActionClient[Any, Any, Any]:
        """An action client shared by every behavior of this context (created on first use).

        ``action_type`` is ``pkg/action/Name`` or a definition class from ``kinema.interfaces.typed``.
        """
        from kinema.interfaces.definition import interface_type_name

        type_name = interface_type_name(action_type, "action")
        return self._endpoint(  # type: ignore[no-any-return]
            ("action", id(node), type_name, name), lambda: node.create_action_client(type_name, name)
        )

    def publisher(
        self, node: Any, message_type: str, topic: str, *, latched: bool = False, qos: QoS | None = None
    ) -> Any:
        """A publisher shared by every behavior of this context (created on first use).

        Publishers stay declared for the context's lifetime, so a subscriber discovered once keeps
        receiving (a publisher made per message could publish before anyone has matched it). ``qos``
        defaults to ROS's default profile (``KEEP_ALL_QOS`` for messages that must not be dropped).
        """
        return self._endpoint(
            ("publisher", id(node), message_type, topic, latched, qos),
            lambda: node.create_publisher(message_type, topic, qos, latched=latched),
        )

    def _endpoint(self, key: tuple[Any, ...], create: Callable[[], Any]) -> Any:
        with self._endpoints_lock:
            endpoint = self._endpoints.get(key)
            if endpoint is None:
                endpoint = create()
                self._endpoints[key] = endpoint
            return endpoint

    def close(self) -> None:
        """Close the clients and publishers this context created (the node itself is the caller's)."""
        with self._endpoints_lock:
            endpoints, self._endpoints = list(self._endpoints.values()), {}
        for endpoint in endpoints:
            endpoint.close()

    @property
    def logger(self) -> BehaviorLogger:
        """A logger to this context's sink without a behavior identity (behaviors use ``self.logger``)."""
        return BehaviorLogger(self.log_sink)

    def logger_for(
        self, *, behavior_id: str = "", node_name: str = "", node_path: str = "", plugin: str = ""
    ) -> BehaviorLogger:
        """A logger whose messages carry the given behavior identity and go to this context's sink."""
        return BehaviorLogger(
            self.log_sink, behavior_id=behavior_id, node_name=node_name, node_path=node_path, plugin=plugin
        )
