"""Node base classes: the contract every built-in and Python-registered node follows.

``execute_tick()`` is what parents call; it evaluates the pre-conditions, calls ``tick()``, wraps any
exception escaping ``tick()`` once into :class:`NodeExecutionError` (the innermost node wins), runs
the post-conditions and records the new status, notifying status observers only on a real change.
SKIPPED is returned to the parent but never stored.

A node type declares its ports with ``@classmethod provided_ports(cls) -> list[PortInfo]`` and is
constructed as ``cls(name, config)``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from kinema.bt.conversions import AnyValue, ConversionError, cast_value, convert_from_string, list_item_type
from kinema.bt.errors import BTError, BTLogicError, BTRuntimeError, NodeExecutionError
from kinema.bt.ports import PortInfo, blackboard_pointer
from kinema.bt.status import FAILURE, IDLE, RUNNING, SKIPPED, SUCCESS, NodeStatus

# A change code's statuses: code % 25 is previous * 5 + new, each an index into this.
_STATUSES = tuple(NodeStatus)

if TYPE_CHECKING:
    from kinema.bt.blackboard import Blackboard
    from kinema.bt.clock import Clock
    from kinema.bt.script import Script
    from kinema.errors import SourceLocation

StatusObserver = Callable[[float, "TreeNode", NodeStatus, NodeStatus], None]

_MISSING: Any = object()
# The port-read caches of a node that has read no port yet (never written: see TreeNode.__init__).
_NOTHING_READ: Any = {}


class _DictOnDemand:
    """A dict attribute of :class:`NodeConfig` kept as None in its slot (``_<name>``) until it is first
    read or set: many nodes have none, and a tree builds faster without allocating them (each
    allocation also brings the next collection nearer). Reading one costs a Python call: the hot
    paths read them once per node (a port's binding is cached) or test the slot itself."""

    def __set_name__(self, owner: type, name: str) -> None:
        self.slot = getattr(owner, "_" + name)  # the slot's member descriptor

    def __get__(self, config: Any, owner: type | None = None) -> Any:
        if config is None:
            return self
        value = self.slot.__get__(config, owner)
        if value is None:
            value = {}
            self.slot.__set__(config, value)
        return value

    def __set__(self, config: Any, value: dict[str, Any]) -> None:
        self.slot.__set__(config, value)


class NodeConfig:
    """Everything a node instance gets from the tree that contains it.

    Attributes:
        blackboard: the blackboard of the (sub)tree the node lives in.
        input_ports / output_ports: port name -> value text from the XML (or the declared default).
        manifest: the node type's manifest (ports, category), or None for ad-hoc nodes.
        uid: unique id inside the tree (1-based, depth-first).
        path: the node's full path.
        enums: the factory's scripting enums.
        pre_conditions / post_conditions: parsed ``_failureIf``... / ``_onSuccess``... scripts.
        other_attributes: attributes that are neither ports nor reserved (``_description``...).
        wake_up: the tree's wake-up signal (None outside a tree).
        clock: the time source of the tree.
        location: where the node is written in its XML file.
    """

    __slots__ = (
        "_input_ports",
        "_other_attributes",
        "_output_ports",
        "_post_conditions",
        "_pre_conditions",
        "blackboard",
        "clock",
        "enums",
        "manifest",
        "path",
        "source_file",
        "source_line",
        "uid",
        "wake_up",
    )

    input_ports: dict[str, Any] = _DictOnDemand()  # type: ignore[assignment]
    output_ports: dict[str, Any] = _DictOnDemand()  # type: ignore[assignment]
    pre_conditions: dict[str, Script] = _DictOnDemand()  # type: ignore[assignment]
    post_conditions: dict[str, Script] = _DictOnDemand()  # type: ignore[assignment]
    other_attributes: dict[str, str] = _DictOnDemand()  # type: ignore[assignment]

    def __init__(self, blackboard: Blackboard | None = None) -> None:
        if blackboard is None:
            from kinema.bt.blackboard import Blackboard

            blackboard = Blackboard.create()
        self.blackboard: Blackboard = blackboard
        self.manifest: Any = None
        self.uid = 0
        self.path = ""
        self.enums: dict[str, int] = {}
        # None stands for empty (see _DictOnDemand): many nodes have no ports, and most no conditions
        # or other attributes.
        self._input_ports: dict[str, Any] | None = None
        self._output_ports: dict[str, Any] | None = None
        self._pre_conditions: dict[str, Script] | None = None
        self._post_conditions: dict[str, Script] | None = None
        self._other_attributes: dict[str, str] | None = None
        self.wake_up: Any = None
        self.clock: Clock | None = None
        self.source_file: str | None = None
        self.source_line = 0

    @property
    def location(self) -> SourceLocation | None:
        """``file:line`` of the node's XML element, if it came from XML."""
        if self.source_file is None:
            return None
        from kinema.errors import SourceLocation

        return SourceLocation(self.source_file, self.source_line)

    @location.setter
    def location(self, value: SourceLocation | None) -> None:
        self.source_file = value.file if value is not None else None
        self.source_line = value.line if value is not None else 0


class _Notifier:
    """A node's change sink while status callbacks observe it and no transition log does."""

    __slots__ = ("node",)

    def __init__(self, node: TreeNode) -> None:
        self.node = node

    def append(self, code: int) -> None:
        self.node._notify_code(code)


class _LoggingNotifier(_Notifier):
    """A node's change sink while both the tree's transition log and status callbacks observe it."""

    __slots__ = ("codes",)

    def __init__(self, codes: list[int], node: TreeNode) -> None:
        super().__init__(node)
        self.codes = codes

    def append(self, code: int) -> None:
        self.codes.append(code)
        self.node._notify_code(code)


class PortError(BTRuntimeError):
    """A port could not be read or written."""


class PortResult:
    """What :meth:`TreeNode.try_get_input` returns: a value, or an error message."""

    __slots__ = ("error", "value")

    def __init__(self, value: Any = None, error: str | None = None) -> None:
        self.value = value
        self.error = error

    @property
    def ok(self) -> bool:
        """True if the value was read."""
        return self.error is None

    def __bool__(self) -> bool:
        return self.error is None

    def __repr__(self) -> str:
        return (
            f"PortResult(value={self.value!r})" if self.error is None else f"PortResult(error={self.error!r})"
        )


class TreeNode:
    """Base class of every node.

    Subclasses implement ``tick()`` (and ``halt()`` when they keep state). They must not block:
    long work belongs in a :class:`StatefulActionNode` that returns RUNNING.
    """

    __slots__ = (
        "__dict__",
        "_bindings",
        "_hooked",
        "_literal_cache",
        "_log",
        "_log_base",
        "_log_codes",
        "_observers",
        "_post_tick",
        "_pre_tick",
        "_status",
        "_watched",
        "config",
        "name",
        "registration_id",
    )

    # A SyncActionNode may never return RUNNING.
    _forbid_running = False

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        self.name = name
        self.config = config if config is not None else NodeConfig()
        self._status = IDLE
        # A tuple, replaced on (un)subscribe: notifying iterates it without copying it.
        self._observers: tuple[StatusObserver, ...] = ()
        # The tree's transition log (``TransitionLog.codes``) while one is attached, and this node's
        # base code in it.
        self._log_codes: list[int] | None = None
        self._log_base = 0
        # Where a change goes while anything observes the node (see _rewire): something with an
        # ``append(code)``, the code being ``_log_base + previous * 5 + new``. None while nothing does.
        self._log: Any = None  # list[int] | _Notifier | None, used only while _watched
        # True while anything observes the node (a callback or a log): the one test on the hot path.
        self._watched = False
        # Filled by the first port reads; until then both are the one shared empty dict (most nodes
        # read no port, and a tree of them skips two allocations a node). Written only after
        # replacing it: see _binding and get_input.
        self._bindings: dict[str, tuple[str | None, Any, Any]] = _NOTHING_READ
        self._literal_cache: dict[tuple[str, Any], Any] = _NOTHING_READ
        manifest = self.config.manifest
        self.registration_id: str = manifest.id if manifest is not None else type(self).__name__
        self._pre_tick: Callable[[TreeNode], NodeStatus] | None = None
        self._post_tick: Callable[[TreeNode, NodeStatus], NodeStatus] | None = None
        config = self.config
        self._hooked = bool(
            config._pre_conditions or config._post_conditions
        )  # _refresh_hooked, no callbacks yet

    def _refresh_hooked(self) -> None:
        # The plain tick path is taken unless the node has conditions or injected callbacks.
        config = self.config
        self._hooked = bool(
            config._pre_conditions or config._post_conditions or self._pre_tick or self._post_tick
        )

    def set_pre_tick_callback(self, callback: Callable[[TreeNode], NodeStatus] | None) -> None:
        """Call ``callback(node)`` before ``tick()`` while the node is not completed.

        If it returns SUCCESS or FAILURE, ``tick()`` is skipped and that is the result (BT.CPP's
        ``setPreTickFunction``, used for breakpoints and substitutions). None removes it.
        """
        self._pre_tick = callback
        self._refresh_hooked()

    def set_post_tick_callback(self, callback: Callable[[TreeNode, NodeStatus], NodeStatus] | None) -> None:
        """Call ``callback(node, status)`` after every tick; SUCCESS/FAILURE returned replace the status."""
        self._post_tick = callback
        self._refresh_hooked()

    # -- identity --------------------------------------------------------------------------------

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        """The ports of this node type (override; default: none)."""
        return []

    @property
    def uid(self) -> int:
        """Unique id of the node inside its tree (1-based)."""
        return self.config.uid

    @property
    def full_path(self) -> str:
        """``<subtree path>/<name>``, with ``::<uid>`` when the node has no explicit name."""
        return self.config.path or self.name

    @property
    def status(self) -> NodeStatus:
        """The stored status (SKIPPED is never stored)."""
        return self._status

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.full_path!r} {self._status.name}>"

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        # A built-in node whose execute_tick runs its own tick() inline (@inlines_tick) would never call
        # a subclass's tick(): such a subclass gets back the execute_tick of its nearest base that calls
        # tick(), so its override runs.
        if "tick" in cls.__dict__ and "execute_tick" not in cls.__dict__:
            if getattr(cls.execute_tick, "inlines_tick", False):
                for base in cls.__mro__[1:]:
                    method = base.__dict__.get("execute_tick")
                    if method is not None and not getattr(method, "inlines_tick", False):
                        cls.execute_tick = method  # type: ignore[method-assign]
                        break

    # -- ticking ---------------------------------------------------------------------------------

    def tick(self) -> NodeStatus:
        """Do the node's work and return its status. Called by ``execute_tick``."""
        raise NotImplementedError(f"{type(self).__name__}.tick() is not implemented")

    def halt(self) -> None:
        """Stop and reset the node (override to cancel work; call the base to reset)."""
        self.reset_status()

    def execute_tick(self) -> NodeStatus:
        """Tick the node with pre/post-conditions; what parents call."""
        if self._hooked:
            return self._execute_tick_hooked()
        try:
            status = self.tick()
        except NodeExecutionError:
            raise
        except Exception as error:
            raise self._wrap_exception(error) from error
        prev = self._status
        if status is not prev:
            if status is SUCCESS or status is FAILURE:
                # Inlined _set_status for the common case: this is the hot path of every tick.
                self._status = status
                if self._watched:
                    self._log.append(self._log_base + prev * 5 + status)
            elif status is not SKIPPED:
                self._set_status(status)
        elif status is IDLE or (status is RUNNING and self._forbid_running):
            self._set_status(status)
        return status

    def _notify(self, prev: NodeStatus, new: NodeStatus) -> None:
        """Report a change already stored (only while ``_watched``; the hot paths inline this call)."""
        self._log.append(self._log_base + prev * 5 + new)

    def _rewire(self) -> None:
        """Point ``_log`` at what observes the node now: the tree's log, the callbacks, both, or nothing.

        One ``append`` per change then serves them all (the log's own list append when only the log
        observes), and the hot paths test one flag.
        """
        codes = self._log_codes
        if not self._observers:
            self._log = codes  # the hot paths' ``self._log.append(code)`` is then CPython's list append
        elif codes is None:
            self._log = _Notifier(self)
        else:
            self._log = _LoggingNotifier(codes, self)
        self._watched = self._log is not None

    def _notify_code(self, code: int) -> None:
        rest = code % 25
        self._notify_observers(_STATUSES[rest // 5], _STATUSES[rest % 5])

    def _notify_observers(self, prev: NodeStatus, new: NodeStatus) -> None:
        clock = self.config.clock
        now = clock.now() if clock is not None else 0.0
        for callback in self._observers:
            callback(now, self, prev, new)

    def _wrap_exception(self, error: Exception) -> NodeExecutionError:
        if isinstance(error, BTError):
            message = error.message
        elif isinstance(error, RecursionError):
            message = "maximum recursion depth exceeded"
        else:
            message = f"{type(error).__name__}: {error}"
        return NodeExecutionError(
            self.name, self.full_path, self.registration_id, message, location=self.config.location
        )

    def _execute_tick_hooked(self) -> NodeStatus:
        config = self.config
        status = self._check_pre_conditions() if config._pre_conditions else None
        if status is None:
            pre_tick = self._pre_tick
            if pre_tick is not None and self._status is not SUCCESS and self._status is not FAILURE:
                override = pre_tick(self)
                if override is SUCCESS or override is FAILURE:
                    status = override
            if status is None:
                try:
                    status = self.tick()
                except NodeExecutionError:
                    raise
                except Exception as error:
                    raise self._wrap_exception(error) from error
        if (status is SUCCESS or status is FAILURE) and config._post_conditions:
            post = config._post_conditions
            script = post.get("_onSuccess" if status is SUCCESS else "_onFailure")
            if script is not None:
                script.run(config.blackboard, config.enums)
            script = post.get("_post")
            if script is not None:
                script.run(config.blackboard, config.enums)
        post_tick = self._post_tick
        if post_tick is not None:
            override = post_tick(self, status)
            if override is SUCCESS or override is FAILURE:
                status = override
        if status is not SKIPPED:
            self._set_status(status)
        return status

    def _check_pre_conditions(self) -> NodeStatus | None:
        config = self.config
        pre = config.pre_conditions
        current = self._status
        for key, result in (("_failureIf", FAILURE), ("_successIf", SUCCESS), ("_skipIf", SKIPPED)):
            script = pre.get(key)
            if script is not None and current is IDLE:
                if _script_bool(script.run(config.blackboard, config.enums)):
                    return result
        script = pre.get("_while")
        if script is not None:
            if current is IDLE:
                if not _script_bool(script.run(config.blackboard, config.enums)):
                    return SKIPPED
            elif current is RUNNING and not _script_bool(script.run(config.blackboard, config.enums)):
                self.halt_node()
                return SKIPPED
        return None

    def _set_status(self, new: NodeStatus) -> None:
        if new.__class__ is not NodeStatus:
            new = _coerce_status(self, new)
        if new is IDLE:
            raise BTRuntimeError(
                f"Node [{self.name}]: you are not allowed to set manually the status to IDLE. "
                "If you know what you are doing (?) use reset_status() instead."
            )
        if new is RUNNING and self._forbid_running:
            raise BTLogicError(f"SyncActionNode MUST never return RUNNING (node '{self.full_path}')")
        prev = self._status
        if prev is new:
            return
        self._status = new
        if self._watched:
            self._notify(prev, new)

    def set_status(self, new: NodeStatus) -> None:
        """Store a status (never IDLE; use :meth:`reset_status`)."""
        self._set_status(new)

    def reset_status(self) -> None:
        """Set the status back to IDLE (observers see the change)."""
        prev = self._status
        if prev is IDLE:
            return
        self._status = IDLE
        if self._watched:
            self._log.append(self._log_base + prev * 5)  # IDLE is 0

    def halt_node(self) -> None:
        """``halt()`` followed by the ``_onHalted`` script."""
        self.halt()
        if self._hooked:
            script = self.config.post_conditions.get("_onHalted")
            if script is not None:
                script.run(self.config.blackboard, self.config.enums)

    def emit_wake_up_signal(self) -> None:
        """Ask the tree to tick again now (interrupts ``Tree.sleep``)."""
        wake_up = self.config.wake_up
        if wake_up is not None:
            wake_up.emit()

    # -- observers -------------------------------------------------------------------------------

    def subscribe_to_status_change(self, callback: StatusObserver) -> Callable[[], None]:
        """Call ``callback(timestamp, node, prev, new)`` on every status change; returns an unsubscriber."""
        self._observers = (*self._observers, callback)
        self._rewire()

        def unsubscribe() -> None:
            if callback in self._observers:
                observers = list(self._observers)
                observers.remove(callback)
                self._observers = tuple(observers)
                self._rewire()

        return unsubscribe

    # -- ports -----------------------------------------------------------------------------------

    def _binding(self, name: str) -> tuple[str | None, Any, Any]:
        binding = self._bindings.get(name)
        if binding is not None:
            return binding
        ports = self.config.input_ports
        if name not in ports:
            raise PortError(
                f"getInput() of node '{self.full_path}' failed because nor the manifest or the XML "
                f"contain the key: [{name}]"
            )
        raw = ports[name]
        key = blackboard_pointer(raw, name) if isinstance(raw, str) else None
        manifest = self.config.manifest
        port_info = manifest.ports.get(name) if manifest is not None else None
        binding = (key, raw, port_info.type if port_info is not None else None)
        if self._bindings is _NOTHING_READ:
            self._bindings = {}
        self._bindings[name] = binding
        return binding

    def get_input(self, name: str, type: Any = None) -> Any:
        """The value of input port ``name``, converted to ``type`` (None: the port's declared type).

        Pass ``AnyValue`` to get the stored value or the literal text without any conversion.

        Raises:
            PortError: the port is missing, its blackboard entry is missing or empty, or the value
                cannot be converted; the message names the node path and the port.
        """
        key, raw, port_type = self._binding(name)
        target = port_type if type is None else type
        if target is AnyValue:
            target = None
        if key is None:
            if raw.__class__ is not str or target is str or target is None:
                return raw
            cache_key = (name, target)
            cached = self._literal_cache.get(cache_key, _MISSING)
            if cached is not _MISSING:
                return list(cached) if cached.__class__ is list else cached
            try:
                value = convert_from_string(target, raw, self.config.enums)
            except BTError as error:
                raise PortError(
                    f"node '{self.full_path}': port [{name}] value \"{raw}\" can not be converted: "
                    f"{error.message}"
                ) from None
            if self._literal_cache is _NOTHING_READ:
                self._literal_cache = {}
            self._literal_cache[cache_key] = value
            return list(value) if value.__class__ is list else value
        entry = self.config.blackboard.get_entry(key)
        if entry is None or entry.value is None:
            raise PortError(
                f"getInput() of node '{self.full_path}' failed because it was unable to find the key "
                f"[{name}] remapped to [{key}]"
            )
        value = entry.value
        try:
            if value.__class__ is str and target is not str and target is not None:
                return convert_from_string(target, value, self.config.enums)
            return cast_value(value, target)
        except BTError as error:
            raise PortError(
                f"node '{self.full_path}': port [{name}] (blackboard key [{key}]) can not be read as "
                f"the requested type: {error.message}"
            ) from None

    def try_get_input(self, name: str, type: Any = None) -> PortResult:
        """Like :meth:`get_input` but never raises: check ``result.ok`` / ``result.error``."""
        try:
            return PortResult(self.get_input(name, type))
        except BTError as error:
            return PortResult(None, error.message)

    def get_input_or(self, name: str, default: Any, type: Any = None) -> Any:
        """The value of input port ``name``, or ``default`` if it cannot be read."""
        result = self.try_get_input(name, type)
        return result.value if result.error is None else default

    def port_blackboard_key(self, name: str) -> str | None:
        """The blackboard key port ``name`` points to, or None for a literal (or a missing port)."""
        raw = self.config.input_ports.get(name, self.config.output_ports.get(name))
        return blackboard_pointer(raw, name) if isinstance(raw, str) else None

    def set_output(self, name: str, value: Any) -> None:
        """Write ``value`` to the blackboard entry output port ``name`` points to.

        Raises:
            PortError: the port is not an output port of this node, or it is not mapped to ``{key}``.
            BTLogicError: the entry already holds an incompatible type.
        """
        ports = self.config.output_ports
        if name not in ports:
            raise PortError(
                f"setOutput() of node '{self.full_path}': output port [{name}] is not declared "
                "or not given in the XML"
            )
        raw = ports[name]
        key = blackboard_pointer(raw, name) if isinstance(raw, str) else None
        if key is None:
            raise PortError(
                f"setOutput() of node '{self.full_path}': port [{name}] requires a blackboard pointer "
                f'like {{key}}, got "{raw}"'
            )
        manifest = self.config.manifest
        port_info = manifest.ports.get(name) if manifest is not None else None
        if port_info is not None and port_info.type is not None and value is not None:
            value = _convert_output(port_info.type, value)
        self.config.blackboard.set(key, value)


def _convert_output(port_type: Any, value: Any) -> Any:
    """Numbers written to a float port are stored as floats, as C++ would have typed them."""
    if port_type is float and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    if list_item_type(port_type) is float and isinstance(value, list):
        return [float(v) if isinstance(v, int) and not isinstance(v, bool) else v for v in value]
    return value


def _coerce_status(node: TreeNode, value: Any) -> NodeStatus:
    if isinstance(value, int) and 0 <= value <= 4:
        return NodeStatus(value)
    raise BTLogicError(f"tick() of node '{node.full_path}' returned {value!r}, not a NodeStatus")


def _script_bool(value: Any) -> bool:
    """``Any::cast<bool>`` of a condition script's result."""
    if isinstance(value, float):
        return value != 0.0
    if isinstance(value, int):
        if value == 0 or value == 1:
            return bool(value)
        raise BTRuntimeError(f"Implicit casting to bool is not allowed (value {value})")
    if value is None:
        raise BTRuntimeError("the condition script returned an empty value")
    if isinstance(value, str):
        raise BTRuntimeError("[Any::convert]: no known safe conversion between [std::string] and [bool]")
    raise BTRuntimeError(f"the condition script returned a value of type {type(value).__name__}, not a bool")


def script_bool(value: Any) -> bool:
    """Public form of the ``cast<bool>`` used for condition scripts."""
    return _script_bool(value)


# -- leaves -----------------------------------------------------------------------------------------


class ActionNode(TreeNode):
    """Base class of actions (leaf nodes that do something)."""

    __slots__ = ()


class SyncActionNode(ActionNode):
    """An action that finishes within one tick: ``tick()`` returns SUCCESS or FAILURE, never RUNNING."""

    __slots__ = ()
    _forbid_running = True


class ConditionNode(TreeNode):
    """A leaf that checks something and returns SUCCESS or FAILURE; it should not change the world."""

    __slots__ = ()


class StatefulActionNode(ActionNode):
    """An action that runs over several ticks.

    ``on_start()`` is called on the first tick, ``on_running()`` on the following ticks while the
    node is RUNNING, and ``on_halted()`` when a RUNNING node is halted. None of them may block.
    """

    __slots__ = ("_halt_requested",)

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._halt_requested = False

    def on_start(self) -> NodeStatus:
        """Called when the node is ticked while IDLE."""
        raise NotImplementedError(f"{type(self).__name__}.on_start() is not implemented")

    def on_running(self) -> NodeStatus:
        """Called on every tick while the node is RUNNING."""
        raise NotImplementedError(f"{type(self).__name__}.on_running() is not implemented")

    def on_halted(self) -> None:
        """Called when the node is halted while RUNNING; cancel the work here."""

    def is_halt_requested(self) -> bool:
        """True once the node has been halted (BT.CPP never clears it)."""
        return self._halt_requested

    def tick(self) -> NodeStatus:
        prev = self._status
        if prev is IDLE:
            status = self.on_start()
            if status is IDLE:
                raise BTLogicError("StatefulActionNode::onStart() must not return IDLE")
            return status
        if prev is RUNNING:
            status = self.on_running()
            if status is IDLE:
                raise BTLogicError("StatefulActionNode::onRunning() must not return IDLE")
            return status
        return prev

    def halt(self) -> None:
        self._halt_requested = True
        if self._status is RUNNING:
            self.on_halted()
        self.reset_status()


class SimpleActionNode(SyncActionNode):
    """A sync action calling ``fn(node) -> NodeStatus`` (``register_simple_action``)."""

    __slots__ = ("_fn",)

    def __init__(self, name: str, config: NodeConfig | None, fn: Callable[[TreeNode], NodeStatus]) -> None:
        super().__init__(name, config)
        self._fn = fn

    def tick(self) -> NodeStatus:
        # BT.CPP sets RUNNING before calling the functor and the result right after it, inside
        # tick() (observers see IDLE -> RUNNING -> result even when a post-condition then throws);
        # the sync-node rule only forbids *returning* RUNNING, so the status is set directly.
        if self._status is IDLE:
            _set_status_unchecked(self, RUNNING)
        status = self._fn(self)
        if status is not self._status and status is not IDLE:
            _set_status_unchecked(self, status)
        return status


class SimpleConditionNode(ConditionNode):
    """A condition calling ``fn(node) -> NodeStatus`` (``register_simple_condition``)."""

    __slots__ = ("_fn",)

    def __init__(self, name: str, config: NodeConfig | None, fn: Callable[[TreeNode], NodeStatus]) -> None:
        super().__init__(name, config)
        self._fn = fn

    def tick(self) -> NodeStatus:
        return self._fn(self)


def inlines_tick(method: Callable[..., NodeStatus]) -> Callable[..., NodeStatus]:
    """Mark an ``execute_tick`` that does its class's ``tick()`` inline instead of calling it (one Python
    frame less per node on the hot path); see ``TreeNode.__init_subclass__`` for subclasses."""
    method.inlines_tick = True  # type: ignore[attr-defined]
    return method


def _set_status_unchecked(node: TreeNode, new: NodeStatus) -> None:
    prev = node._status
    if prev is new:
        return
    node._status = new
    if node._watched:
        node._log.append(node._log_base + prev * 5 + new)


# -- composites -------------------------------------------------------------------------------------


class ControlNode(TreeNode):
    """A node with one or more children."""

    __slots__ = ("children",)

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self.children: list[TreeNode] = []

    def add_child(self, child: TreeNode) -> None:
        """Append a child (done by the tree builder)."""
        self.children.append(child)

    def halt(self) -> None:
        self.reset_children()
        self.reset_status()

    def reset_children(self) -> None:
        """Halt every RUNNING child, then reset every child to IDLE."""
        for child in self.children:
            status = child._status
            if status is not IDLE:
                if status is RUNNING:
                    child.halt_node()
                    child.reset_status()
                elif child._watched:
                    # reset_status() inlined: an observed tree resets every completed child
                    child._status = IDLE
                    child._log.append(child._log_base + status * 5)  # IDLE is 0
                else:
                    child._status = IDLE

    def halt_child(self, index: int) -> None:
        """Halt child ``index`` if RUNNING, then reset it to IDLE."""
        child = self.children[index]
        if child._status is RUNNING:
            child.halt_node()
        child.reset_status()

    def halt_children(self, first: int = 0) -> None:
        """``halt_child(i)`` for every child from ``first`` on."""
        for i in range(first, len(self.children)):
            self.halt_child(i)


class DecoratorNode(TreeNode):
    """A node with exactly one child; the child is reset after it completes."""

    __slots__ = ("child",)

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self.child: TreeNode | None = None

    def set_child(self, child: TreeNode) -> None:
        """Attach the child (done by the tree builder)."""
        if self.child is not None:
            raise BTError(f"Decorator [{self.name}] has already a child assigned")
        self.child = child

    @property
    def children(self) -> list[TreeNode]:
        """The child as a one-element list (empty while unset)."""
        return [self.child] if self.child is not None else []

    def execute_tick(self) -> NodeStatus:
        # TreeNode.execute_tick inlined (one call less per decorator), then the completed child is reset.
        if self._hooked:
            status = self._execute_tick_hooked()
        else:
            try:
                status = self.tick()
            except NodeExecutionError:
                raise
            except Exception as error:
                raise self._wrap_exception(error) from error
            prev = self._status
            if status is not prev:
                if status is SUCCESS or status is FAILURE:
                    self._status = status
                    if self._watched:
                        self._log.append(self._log_base + prev * 5 + status)
                elif status is not SKIPPED:
                    self._set_status(status)
            elif status is IDLE or (status is RUNNING and self._forbid_running):
                self._set_status(status)
        child = self.child
        if child is not None:
            child_status = child._status
            if child_status is SUCCESS or child_status is FAILURE:
                child.reset_status()
        return status

    def halt(self) -> None:
        self.reset_child()
        self.reset_status()

    def reset_child(self) -> None:
        """Halt the child if RUNNING, then reset it to IDLE."""
        child = self.child
        if child is None:
            return
        if child._status is RUNNING:
            child.halt_node()
        child.reset_status()

    def halt_child(self) -> None:
        """Same as :meth:`reset_child`."""
        self.reset_child()


class SimpleDecoratorNode(DecoratorNode):
    """A decorator calling ``fn(child_status, node) -> NodeStatus``."""

    __slots__ = ("_fn",)

    def __init__(
        self, name: str, config: NodeConfig | None, fn: Callable[[NodeStatus, TreeNode], NodeStatus]
    ) -> None:
        super().__init__(name, config)
        self._fn = fn

    def tick(self) -> NodeStatus:
        assert self.child is not None
        return self._fn(self.child.execute_tick(), self)


def node_children(node: TreeNode) -> list[TreeNode]:
    """The children of any node (empty for leaves)."""
    if isinstance(node, ControlNode):
        return node.children
    if isinstance(node, DecoratorNode):
        return [node.child] if node.child is not None else []
    return []


__all__ = [
    "ActionNode",
    "ConditionNode",
    "ControlNode",
    "ConversionError",
    "DecoratorNode",
    "NodeConfig",
    "PortError",
    "PortResult",
    "SimpleActionNode",
    "SimpleConditionNode",
    "SimpleDecoratorNode",
    "StatefulActionNode",
    "SyncActionNode",
    "TreeNode",
]
