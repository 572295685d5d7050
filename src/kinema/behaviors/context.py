"""What a behavior reaches its cell through: transport node, clock, robot model, planning scene, joint
states, frames, cameras, config, log sink.

One :class:`BehaviorContext` is shared by every behavior of a tree (MoveIt Pro's
``BehaviorContext``/"shared resources"). The runtime builds it once per cell with its transport node, the
runtime clock (sim time in simulation), the robot model provider and the config, and passes it to
:meth:`kinema.plugins.BehaviorRegistry.create_factory`. The services a behavior uses are members of it,
made on first use (a behavior that never plans never loads the planning scene); a behavior never keeps
per-cell state in a module-level table, it asks its context (:meth:`BehaviorContext.shared`).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TypeVar, overload

from kinema.behaviors.logger import BehaviorLogger, LogSink
from kinema.errors import ObjectiveError

if TYPE_CHECKING:
    import numpy as np

    from kinema.bt import Clock
    from kinema.config.cell import CellSettings
    from kinema.config.inheritance import ResolvedConfig
    from kinema.interfaces.definition import (
        ActionDefinition,
        FeedbackT,
        GoalT,
        RequestT,
        ResponseT,
        ResultT,
        ServiceDefinition,
    )
    from kinema.motion.cell_frames import CellFrames
    from kinema.motion.joint_state_monitor import JointStateMonitor
    from kinema.motion.planning_scene import PlanningScene
    from kinema.motion.robot_model import RobotModel
    from kinema.transport import ActionClient, Node, QoS, ServiceClient

T = TypeVar("T")
PlanningSceneListener = Callable[["PlanningScene"], None]


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
        planning_scene: the planning scene, or a callable of this context that makes it on first use;
            by default the static geometry of the config's MuJoCo scene (empty without one).
    """

    def __init__(
        self,
        node: Node | None = None,
        *,
        clock: Clock | None = None,
        log_sink: LogSink | None = None,
        robot_model: RobotModel | Callable[[], RobotModel | None] | None = None,
        config: ResolvedConfig | None = None,
        planning_scene: PlanningScene | Callable[[BehaviorContext], PlanningScene] | None = None,
    ) -> None:
        if clock is None:
            from kinema.bt import WallClock

            clock = WallClock()
        self.node: Node | None = node
        self.config: ResolvedConfig | None = config
        self.clock = clock
        self.log_sink = log_sink if log_sink is not None else LogSink()
        self._robot_model: Any = robot_model
        self._cell: Any = _UNSET
        self._robot_model_lock = threading.Lock()
        self._endpoints: dict[tuple[Any, ...], Any] = {}
        self._endpoints_lock = threading.Lock()
        self._scene: PlanningScene | None = None
        self._scene_provider: Callable[[BehaviorContext], PlanningScene] = _default_planning_scene
        if callable(planning_scene):
            self._scene_provider = planning_scene
        else:
            self._scene = planning_scene
        self._scene_listeners: list[PlanningSceneListener] = []
        self._services: dict[str, Any] = {}
        # Re-entrant: a service made on first use may use another (the frames read the planning scene).
        self._services_lock = threading.RLock()

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
    def robot_model(self) -> RobotModel | None:
        """The robot model (built on first access when a provider callable was given); None if unset."""
        with self._robot_model_lock:
            if callable(self._robot_model) and not isinstance(self._robot_model, type):
                self._robot_model = self._robot_model()
            model: RobotModel | None = self._robot_model
            return model

    def set_robot_model(self, model_or_provider: Any) -> None:
        """Set the robot model, or a zero-argument callable that builds it on first use."""
        with self._robot_model_lock:
            self._robot_model = model_or_provider

    # -- the cell's services -------------------------------------------------------------------------

    @property
    def planning_scene(self) -> PlanningScene:
        """The cell's planning scene: what planning checks, ``/monitored_planning_scene`` publishes and
        ``/get_planning_scene`` serves (made on first use; see the ``planning_scene`` argument)."""
        with self._services_lock:
            if self._scene is not None:
                return self._scene
            scene = self._scene = self._scene_provider(self)
            listeners = list(self._scene_listeners)
        for listener in listeners:
            listener(scene)
        return scene

    @property
    def loaded_planning_scene(self) -> PlanningScene | None:
        """The planning scene if it was made or set, else None (reading this loads nothing)."""
        with self._services_lock:
            return self._scene

    def set_planning_scene(self, scene: PlanningScene) -> None:
        """Plan against (and serve) ``scene`` in every behavior of this context from now on."""
        with self._services_lock:
            self._scene = scene
            listeners = list(self._scene_listeners)
        for listener in listeners:
            listener(scene)

    def on_planning_scene(self, listener: PlanningSceneListener) -> None:
        """Call ``listener`` with the planning scene once it is made, and with each one set after it (the
        runtime publishes them)."""
        with self._services_lock:
            self._scene_listeners.append(listener)
            scene = self._scene
        if scene is not None:
            listener(scene)

    @property
    def joint_states(self) -> JointStateMonitor:
        """The cell's joint state monitor (``/joint_states``, subscribed on first use).

        Raises:
            ObjectiveError: the context has no transport node.
        """
        from kinema.motion.joint_state_monitor import JointStateMonitor

        return self.shared("joint_states", lambda: JointStateMonitor(self.require_node()))

    @property
    def frames(self) -> CellFrames:
        """The cell's frames: robot links at a configuration, cameras, simulated and planning-scene
        objects (``frames.tree(q)`` is a :class:`~kinema.motion.FrameTree`)."""
        from kinema.motion.cell_frames import CellFrames

        return self.shared("frames", lambda: CellFrames(self))

    @property
    def cameras(self) -> dict[str, np.ndarray]:
        """``world_T_camera`` of the cell's world-fixed cameras (of the config's MuJoCo scene)."""
        return self.frames.cameras

    def shared(self, key: str, create: Callable[[], T]) -> T:
        """The value this context keeps under ``key``, made by ``create`` on first use.

        Per-cell state of a behavior family (a cache, a counter) lives here, so two cells in one process
        never share it and it goes away with the context.
        """
        with self._services_lock:
            if key not in self._services:
                self._services[key] = create()
            value: T = self._services[key]
            return value

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
        """Close the clients, publishers and subscriptions this context created (the node itself is the
        caller's)."""
        with self._endpoints_lock:
            endpoints, self._endpoints = list(self._endpoints.values()), {}
        for endpoint in endpoints:
            endpoint.close()
        with self._services_lock:
            monitor = self._services.pop("joint_states", None)
        if monitor is not None:
            monitor.close()

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


def _default_planning_scene(context: BehaviorContext) -> PlanningScene:
    """The static geometry of the config's MuJoCo scene (tables, walls, trays), without the robot's own
    links; an empty scene without a MuJoCo scene."""
    from kinema.motion.planning_scene import PlanningScene

    config = context.config
    path = config.mujoco_model_path if config is not None else None
    if path is None:
        return PlanningScene()
    model = context.robot_model
    return PlanningScene.from_mjcf(path, model.link_names if model is not None else ())
