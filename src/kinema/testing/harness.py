"""Run behaviors and objectives in a test: tick a behavior with inputs, build a tree, run an objective.

These are the functions behind the pytest fixtures of :mod:`kinema.testing.plugin`; they also work
without pytest. Every run uses a fresh factory bound to a :class:`~kinema.behaviors.BehaviorContext`
(a transport node when the behavior needs one), exactly as the objective server builds one per run.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

from kinema.behaviors.context import BehaviorContext
from kinema.behaviors.logger import LogMessage
from kinema.bt import Blackboard, NodeStatus, PortDirection, Tree
from kinema.errors import PluginError, did_you_mean
from kinema.plugins.registration import validate_registration
from kinema.plugins.registry import BehaviorRegistry

DEFAULT_TIMEOUT = 10.0
_TICK_PERIOD = 0.005


@dataclass
class BehaviorRun:
    """The outcome of :func:`tick_behavior`.

    Attributes:
        status: the final status (SUCCESS or FAILURE).
        outputs: output (and bidirectional) port name -> value written, for the ports that were written.
        messages: the behavior's ``publish_*`` messages, in order.
        ticks: how many times the tree was ticked.
    """

    status: NodeStatus
    outputs: dict[str, Any]
    messages: list[LogMessage] = field(default_factory=list)
    ticks: int = 0

    @property
    def toasts(self) -> list[str]:
        """The texts of :attr:`messages`."""
        return [message.text for message in self.messages]


@dataclass
class ObjectiveRunResult:
    """The outcome of :func:`run_objective`: status, the root blackboard's values, toasts."""

    status: NodeStatus
    blackboard: dict[str, Any]
    messages: list[LogMessage] = field(default_factory=list)
    ticks: int = 0

    @property
    def toasts(self) -> list[str]:
        """The texts of :attr:`messages`."""
        return [message.text for message in self.messages]


def registry_of(behaviors: Iterable[type], plugin: str = "test") -> BehaviorRegistry:
    """A registry of ``behaviors`` (each under its class name), as if one plugin registered them."""
    registrations = {}
    for cls in behaviors:
        record = validate_registration(cls, None, plugin)
        registrations[record.behavior_id] = record
    return BehaviorRegistry(registrations)


def _context(context: BehaviorContext | None, node: Any) -> BehaviorContext:
    if context is not None:
        return context
    return BehaviorContext(node)


def _value(blackboard: Blackboard, key: str) -> Any:
    """The value of ``key``, or None when the entry does not exist or was never written."""
    entry = blackboard.get_entry(key)
    return entry.value if entry is not None else None


def tick_until_done(tree: Tree, timeout: float = DEFAULT_TIMEOUT) -> tuple[NodeStatus, int]:
    """Tick ``tree`` until it is not RUNNING; halt it and raise TimeoutError after ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    ticks = 0
    while True:
        status = tree.tick_once()
        ticks += 1
        if status is not NodeStatus.RUNNING:
            return status, ticks
        if time.monotonic() >= deadline:
            tree.halt_tree()
            raise TimeoutError(f"the tree was still RUNNING after {timeout:g} s ({ticks} ticks)")
        tree.sleep(_TICK_PERIOD)


def tick_behavior(
    behavior: type,
    inputs: Mapping[str, Any] | None = None,
    *,
    node: Any = None,
    context: BehaviorContext | None = None,
    behavior_id: str | None = None,
    timeout: float = DEFAULT_TIMEOUT,
) -> BehaviorRun:
    """Run one behavior to completion with ``inputs`` and return its status, outputs and toasts.

    Args:
        behavior: the behavior class.
        inputs: port name -> value (any Python value: it is put on the blackboard, so no string
            conversion is involved); ports not given take their defaults.
        node: a transport node for behaviors that use services, actions or topics.
        context: a full context instead of ``node`` (clock, robot model, log sink).
        behavior_id: the ID to register it under (default: the class name).
        timeout: seconds before the run is halted and TimeoutError is raised.

    Raises:
        PluginError: the class is not a valid behavior, or an input names no port (with the valid ones).
        TimeoutError: still RUNNING after ``timeout``.
    """
    record = validate_registration(behavior, behavior_id, "test")
    ports = {port.name: port for port in record.ports}
    inputs = dict(inputs or {})
    unknown = [name for name in inputs if name not in ports]
    if unknown:
        raise PluginError(
            f"behavior '{record.behavior_id}' has no port '{unknown[0]}'; {did_you_mean(unknown[0], ports)}"
        )
    context = _context(context, node)
    messages: list[LogMessage] = []
    unsubscribe = context.log_sink.subscribe(messages.append)
    try:
        factory = BehaviorRegistry({record.behavior_id: record}).create_factory(context)
        blackboard = Blackboard.create()
        attributes: dict[str, str] = {}
        for name, port in ports.items():
            if port.direction is not PortDirection.INPUT:
                attributes[name] = "{" + name + "}"
        for name, value in inputs.items():
            blackboard.set(name, value)
            attributes[name] = "{" + name + "}"
        rendered = " ".join(f"{name}={quoteattr(value)}" for name, value in attributes.items())
        xml = (
            '<root BTCPP_format="4"><BehaviorTree ID="TickBehavior">'
            f"<{record.behavior_id} {rendered}/></BehaviorTree></root>"
        )
        tree = factory.create_tree_from_text(xml, blackboard, filename=f"<tick {record.behavior_id}>")
        status, ticks = tick_until_done(tree, timeout)
        outputs = {
            name: _value(blackboard, name)
            for name, port in ports.items()
            if port.direction is not PortDirection.INPUT and _value(blackboard, name) is not None
        }
        return BehaviorRun(status, outputs, messages, ticks)
    finally:
        unsubscribe()


def build_tree(
    xml: str | Path,
    *,
    registry: BehaviorRegistry | None = None,
    behaviors: Iterable[type] = (),
    node: Any = None,
    context: BehaviorContext | None = None,
    blackboard: Blackboard | None = None,
) -> Tree:
    """Build the main tree of ``xml`` (text or a file) with ``registry`` and/or ``behaviors``.

    Raises:
        ObjectiveError: the XML is invalid or uses an unknown behavior or port (with file:line).
    """
    return _build(xml, registry, behaviors, _context(context, node), blackboard)[0]


def _build(
    xml: str | Path,
    registry: BehaviorRegistry | None,
    behaviors: Iterable[type],
    context: BehaviorContext,
    blackboard: Blackboard | None,
) -> tuple[Tree, Any]:
    """The main tree of ``xml`` and the model of the ports its objective declares (None if none)."""
    from kinema.config.cell import substitute_config_defaults

    combined = dict(registry or {})
    combined.update(registry_of(behaviors))
    factory = BehaviorRegistry(combined).create_factory(context)
    library = factory.library
    before = set(library.trees)
    if isinstance(xml, Path):
        root = factory.register_behavior_tree_from_file(xml)
    else:
        root = factory.register_behavior_tree_from_text(xml)
    # As the runtime does: a subtree port default "$(config KEY)" is the context's config value.
    substitute_config_defaults(library.subtree_models, context.config)
    tree = factory.create_tree(library.main_tree_of(root, before), blackboard)
    main = tree.subtrees[0].tree_id if tree.subtrees else ""
    return tree, factory.library.subtree_models.get(main)


def run_objective(
    xml: str | Path,
    *,
    registry: BehaviorRegistry | None = None,
    behaviors: Iterable[type] = (),
    node: Any = None,
    context: BehaviorContext | None = None,
    timeout: float = DEFAULT_TIMEOUT,
    overrides: Mapping[str, Any] | None = None,
) -> ObjectiveRunResult:
    """Build the main tree of ``xml`` and tick it to completion; return status, blackboard and toasts.

    As the runtime runs an objective on its own: the ports it declares start from their defaults, and
    ``overrides`` (port name -> value; a string is read as YAML, as ``kinema objective run -p`` gives
    it) replace them. A behavior that raises lets its exception through, so that pytest shows where.

    Raises:
        ObjectiveError: the XML does not build, or an override names no port or does not convert.
    """
    from kinema.runtime.overrides import ParameterOverride, apply_overrides, model_defaults

    context = _context(context, node)
    messages: list[LogMessage] = []
    unsubscribe = context.log_sink.subscribe(messages.append)
    try:
        blackboard = Blackboard.create()
        tree, model = _build(xml, registry, behaviors, context, blackboard)
        given = [
            ParameterOverride(name, value, from_yaml=isinstance(value, str))
            for name, value in (overrides or {}).items()
        ]
        apply_overrides(
            tree,
            given,
            objective_name=tree.subtrees[0].tree_id if tree.subtrees else "",
            defaults=model_defaults(model),
            parameters=tuple(model.ports) if model is not None else (),
        )
        status, ticks = tick_until_done(tree, timeout)
        values = {key: _value(blackboard, key) for key in blackboard.keys()}
        return ObjectiveRunResult(status, values, messages, ticks)
    finally:
        unsubscribe()


@contextlib.contextmanager
def publish_repeatedly(
    node: Any, message_type: str, topic: str, message: Any, period: float = 0.02
) -> Iterator[None]:
    """Publish ``message`` on ``topic`` every ``period`` seconds while the ``with`` block runs.

    For testing behaviors that wait for the *next* message: whenever they subscribe, one arrives.
    """
    publisher = node.create_publisher(message_type, topic)
    stop = threading.Event()

    def loop() -> None:
        while not stop.is_set():
            publisher.publish(_message(message_type, message))
            stop.wait(period)

    thread = threading.Thread(target=loop, name=f"kinema-test-publish{topic}", daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join(timeout=5)
        publisher.close()


def _message(message_type: str, message: Any) -> Any:
    if isinstance(message, dict):
        from kinema.transport import from_dict

        return from_dict(message_type, message)
    return message


@dataclass
class InProcessRuntime:
    """A Kinema runtime (the agent) serving in this process, and an SDK client connected to it.

    Attributes:
        client: a :class:`kinema.sdk.ObjectiveClient` on the runtime's private network.
        agent: the running :class:`kinema.runtime.agent.Agent`.
        session: the private transport session both use (make more nodes on it for test servers).
    """

    client: Any
    agent: Any
    session: Any


@contextlib.contextmanager
def runtime_in_process(
    config: str | None = None,
    *,
    workspace: Path | None = None,
    objective_dirs: Iterable[Path] = (),
    clock: str = "wall",
    hot_reload: bool = False,
) -> Iterator[InProcessRuntime]:
    """Run the agent for ``config`` in this process on a private network; yield it with a client.

    Args:
        config: the config package (None: only ``objective_dirs`` and the engine's built-in nodes).
        workspace: where to resolve ``config`` (default: the active workspace).
        objective_dirs: extra objective folders.
        clock: ``wall`` (default; no simulator is needed to advance time) or ``sim`` / ``auto``.
        hot_reload: watch behavior packages and objective folders, as ``kinema run`` does.
    """
    from kinema.runtime.agent_process import AgentOptions, build_agent
    from kinema.sdk import ObjectiveClient
    from kinema.transport import open_session

    session = open_session([])
    agent = None
    client = None
    try:
        options = AgentOptions(
            config=config,
            workspace=workspace,
            objective_dirs=[Path(folder) for folder in objective_dirs],
            clock=clock,  # type: ignore[arg-type]
            hot_reload=hot_reload,
        )
        agent = build_agent(options, session)
        agent.start()
        client = ObjectiveClient(session=session)
        client.wait_for_runtime()
        yield InProcessRuntime(client, agent, session)
    finally:
        if client is not None:
            client.close()
        if agent is not None:
            agent.close()
        session.close()


def load_behavior_package(folder: Path) -> BehaviorRegistry:
    """Load the behavior package at ``folder`` by path, as the runtime does, and return its registry.

    Raises:
        PluginError: the folder declares no ``kinema.behaviors`` entry point, or a plugin fails to load.
    """
    from kinema.plugins.discovery import PluginSource, read_behavior_package
    from kinema.plugins.host import BehaviorHost

    specs = read_behavior_package(Path(folder), PluginSource.WORKSPACE)
    if not specs:
        raise PluginError(
            f"{folder} is not a behavior package: its pyproject.toml declares no "
            '[project.entry-points."kinema.behaviors"]'
        )
    host = BehaviorHost([spec.name for spec in specs])
    report = host.load_specs(specs)
    report.raise_for_errors()
    return host.registry
