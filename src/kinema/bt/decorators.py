"""Built-in decorators (reference §2.4). Time-based ones use the tree's clock."""

from __future__ import annotations

from collections import deque
from typing import Any

from kinema.bt.clock import WakeUpTimer
from kinema.bt.conversions import Unsigned, convert_from_string, list_item_type
from kinema.bt.errors import BTLogicError, BTRuntimeError, NodeExecutionError, ScriptParseError
from kinema.bt.node import (
    DecoratorNode,
    NodeConfig,
    PortError,
    _set_status_unchecked,
    inlines_tick,
    script_bool,
)
from kinema.bt.ports import PortInfo, bidirectional_port, blackboard_pointer, input_port, output_port
from kinema.bt.script import Script, parse_script
from kinema.bt.status import FAILURE, IDLE, RUNNING, SKIPPED, SUCCESS, NodeStatus


def _idle_child(node: DecoratorNode) -> BTLogicError:
    return BTLogicError(f"[{node.name}]: A children should not return IDLE")


def _required(node: DecoratorNode, port: str, node_kind: str) -> Any:
    try:
        return node.get_input(port)
    except PortError as error:
        raise BTRuntimeError(f"Missing parameter [{port}] in {node_kind}: {error.message}") from None


class _ResultMappingDecorator(DecoratorNode):
    """Ticks the child and maps a completed result (Inverter, ForceSuccess, ForceFailure);
    RUNNING and SKIPPED pass through."""

    _on_success = SUCCESS
    _on_failure = FAILURE

    def tick(self) -> NodeStatus:
        # What the execute_tick below does inline; this plain form serves nodes with conditions or
        # callbacks (DecoratorNode.execute_tick's hooked path).
        _set_status_unchecked(self, RUNNING)
        child = self.child
        assert child is not None
        status = child.execute_tick()
        if status is SUCCESS or status is FAILURE:
            self.reset_child()
            return self._on_success if status is SUCCESS else self._on_failure
        if status is RUNNING or status is SKIPPED:
            return status
        raise _idle_child(self)

    @inlines_tick
    def execute_tick(self) -> NodeStatus:
        # DecoratorNode.execute_tick fused with tick() (one call less per decorator; these and SubTree
        # are the decorators of nearly every tree), same statuses, transitions and errors.
        if self._hooked:
            return DecoratorNode.execute_tick(self)
        try:
            if self._status is not RUNNING:
                was = self._status
                self._status = RUNNING
                if self._watched:
                    self._log.append(self._log_base + was * 5 + RUNNING)
            child = self.child
            assert child is not None
            status = child.execute_tick()
            if status is SUCCESS or status is FAILURE:
                done = child._status
                if done is RUNNING:
                    self.reset_child()
                else:
                    child._status = IDLE
                    if child._watched and done is not IDLE:
                        child._log.append(child._log_base + done * 5)  # IDLE is 0
                result = self._on_success if status is SUCCESS else self._on_failure
            elif status is RUNNING or status is SKIPPED:
                return status  # stored already (RUNNING), or never stored (SKIPPED)
            else:
                raise _idle_child(self)
        except NodeExecutionError:
            raise
        except Exception as error:
            raise self._wrap_exception(error) from error
        prev = self._status
        if result is not prev:
            self._status = result
            if self._watched:
                self._log.append(self._log_base + prev * 5 + result)
        return result


class InverterNode(_ResultMappingDecorator):
    """SUCCESS <-> FAILURE; RUNNING and SKIPPED pass through."""

    _on_success = FAILURE
    _on_failure = SUCCESS


class ForceSuccessNode(_ResultMappingDecorator):
    """A completed child becomes SUCCESS; RUNNING and SKIPPED pass through."""

    _on_success = SUCCESS
    _on_failure = SUCCESS


class ForceFailureNode(_ResultMappingDecorator):
    """A completed child becomes FAILURE; RUNNING and SKIPPED pass through."""

    _on_success = FAILURE
    _on_failure = FAILURE


class KeepRunningUntilFailureNode(DecoratorNode):
    """RUNNING while the child succeeds; FAILURE when it fails (a SKIPPED child gives RUNNING)."""

    def tick(self) -> NodeStatus:
        _set_status_unchecked(self, RUNNING)
        assert self.child is not None
        status = self.child.execute_tick()
        if status is FAILURE:
            self.reset_child()
            return FAILURE
        if status is SUCCESS:
            self.reset_child()
            return RUNNING
        return self._status


class RepeatNode(DecoratorNode):
    """Ticks the child until it succeeded ``num_cycles`` times (-1: forever); FAILURE stops."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "num_cycles",
                int,
                description="Repeat a successful child up to N times. Use -1 to create an infinite loop.",
            )
        ]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._count = 0

    def tick(self) -> NodeStatus:
        cycles = _required(self, "num_cycles", "RepeatNode")
        do_loop = self._count < cycles or cycles == -1
        _set_status_unchecked(self, RUNNING)
        child = self.child
        assert child is not None
        while do_loop:
            prev = child._status
            status = child.execute_tick()
            if status is SUCCESS:
                self._count += 1
                do_loop = self._count < cycles or cycles == -1
                self.reset_child()
                if prev is IDLE and do_loop:
                    self.emit_wake_up_signal()
                    return RUNNING
            elif status is FAILURE:
                self._count = 0
                self.reset_child()
                return FAILURE
            elif status is RUNNING:
                return RUNNING
            elif status is SKIPPED:
                self.reset_child()
                return SKIPPED
            else:
                raise _idle_child(self)
        self._count = 0
        return SUCCESS

    def halt(self) -> None:
        self._count = 0
        DecoratorNode.halt(self)


class RetryNode(DecoratorNode):
    """Ticks the child until it succeeds, up to ``num_attempts`` failures (-1: forever)."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "num_attempts",
                int,
                description="Execute again a failing child up to N times. Use -1 to create an infinite loop.",
            )
        ]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._tries = 0

    def tick(self) -> NodeStatus:
        attempts = _required(self, "num_attempts", "RetryNode")
        do_loop = self._tries < attempts or attempts == -1
        _set_status_unchecked(self, RUNNING)
        child = self.child
        assert child is not None
        while do_loop:
            prev = child._status
            status = child.execute_tick()
            if status is SUCCESS:
                self._tries = 0
                self.reset_child()
                return SUCCESS
            if status is FAILURE:
                self._tries += 1
                attempts = self.get_input_or("num_attempts", attempts)
                do_loop = self._tries < attempts or attempts == -1
                self.reset_child()
                if prev is IDLE and do_loop:
                    self.emit_wake_up_signal()
                    return RUNNING
            elif status is RUNNING:
                return RUNNING
            elif status is SKIPPED:
                self.reset_child()
                return SKIPPED
            else:
                raise _idle_child(self)
        self._tries = 0
        return FAILURE

    def halt(self) -> None:
        self._tries = 0
        DecoratorNode.halt(self)


class TimeoutNode(DecoratorNode):
    """Halts a child still RUNNING after ``msec`` milliseconds (of the tree's clock) and fails."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "msec",
                Unsigned,
                description="After a certain amount of time, halt() the child if it is still running.",
            )
        ]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._started = False
        # Fires on the clock's thread; the tick thread halts the child when it sees the flag.
        self._timer = WakeUpTimer(self, "TimeoutNode")

    def tick(self) -> NodeStatus:
        msec = _required(self, "msec", "TimeoutNode")
        if msec < 0:
            raise BTRuntimeError(f"TimeoutNode '{self.full_path}': msec must not be negative ({msec})")
        child = self.child
        assert child is not None
        if not self._started:
            self._started = True
            _set_status_unchecked(self, RUNNING)
            self._timer.fired.clear()
            if msec > 0:
                self._timer.start(msec / 1000.0)
        if self._timer.fired.is_set() and child._status is RUNNING:
            self.reset_child()
            self._started = False
            self._timer.fired.clear()
            return FAILURE
        status = child.execute_tick()
        if status is SUCCESS or status is FAILURE:
            self._started = False
            self._timer.cancel()
            self.reset_child()
        return status

    def halt(self) -> None:
        self._started = False
        self._timer.cancel()
        DecoratorNode.halt(self)


class DelayNode(DecoratorNode):
    """Returns RUNNING for ``delay_msec`` milliseconds (of the tree's clock), then ticks the child."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [input_port("delay_msec", Unsigned, description="Tick the child after a few milliseconds")]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._started = False
        self._timer = WakeUpTimer(self, "DelayNode")

    def tick(self) -> NodeStatus:
        msec = _required(self, "delay_msec", "DelayNode")
        if msec < 0:
            raise BTRuntimeError(f"DelayNode '{self.full_path}': delay_msec must not be negative ({msec})")
        if not self._started:
            self._timer.fired.clear()
            self._started = True
            _set_status_unchecked(self, RUNNING)
            self._timer.start(msec / 1000.0)
        if self._timer.fired.is_set():
            assert self.child is not None
            status = self.child.execute_tick()
            if status is SUCCESS or status is FAILURE:
                self._started = False
                self.reset_child()
            return status
        return RUNNING

    def halt(self) -> None:
        self._started = False
        self._timer.cancel()
        DecoratorNode.halt(self)


class RunOnceNode(DecoratorNode):
    """Ticks the child until it completes once; then SKIPPED forever (or the stored result)."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "then_skip",
                bool,
                True,
                "If true, skip after the first execution, otherwise return the same NodeStatus "
                "returned once by the child.",
            )
        ]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._done = False
        self._returned = IDLE

    def tick(self) -> NodeStatus:
        skip = self.get_input_or("then_skip", True)
        if self._done:
            return SKIPPED if skip else self._returned
        _set_status_unchecked(self, RUNNING)
        assert self.child is not None
        status = self.child.execute_tick()
        if status is SUCCESS or status is FAILURE:
            self._done = True
            self._returned = status
            self.reset_child()
        return status


class PreconditionNode(DecoratorNode):
    """Ticks the child only if the ``if`` script is true, else returns ``else`` (checked once per run)."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("if", str),
            input_port("else", NodeStatus, FAILURE, "Return status if condition is false"),
        ]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._children_running = False
        self._script: Script | None = None
        self._script_code: str | None = None
        # BT.CPP parses the condition in the constructor: a missing or malformed literal `if`
        # fails createTree (a {pointer} is read and parsed when ticked).
        code = self.config.input_ports.get("if")
        if code is None:
            raise BTRuntimeError(f"Missing parameter [if] in Precondition '{self.full_path}'")
        if code and blackboard_pointer(code, "if") is None:
            try:
                self._script = parse_script(code)
            except ScriptParseError as error:
                raise BTRuntimeError(
                    f"Error in the script \"{code}\" of node '{self.full_path}': {error.message}"
                ) from None
            self._script_code = code

    def _executor(self) -> Script:
        code = self.get_input("if", str)
        if self._script is None or code != self._script_code:
            self._script = parse_script(code)
            self._script_code = code
        return self._script

    def tick(self) -> NodeStatus:
        script = self._executor()
        try:
            else_status = self.get_input("else")
        except PortError:
            raise BTRuntimeError("Missing parameter [else] in Precondition") from None
        if not self._children_running:
            self._children_running = script_bool(script.run(self.config.blackboard, self.config.enums))
        if not self._children_running:
            return else_status
        assert self.child is not None
        status = self.child.execute_tick()
        if status is SUCCESS or status is FAILURE:
            self.reset_child()
            self._children_running = False
        return status


def entry_key_of(node: Any) -> str:
    """The blackboard key named by an ``entry`` port (``key`` or ``{key}``)."""
    raw = node.config.input_ports.get("entry")
    if not raw or not isinstance(raw, str):
        raise BTLogicError(f"Missing port 'entry' in {node.name}")
    stripped = raw.strip()
    if len(stripped) >= 3 and stripped[0] == "{" and stripped[-1] == "}":
        return stripped[1:-1]
    return raw


class EntryUpdatedDecorator(DecoratorNode):
    """Ticks the child only when the ``entry`` blackboard key was written since the last look."""

    _if_not_updated = SKIPPED

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [input_port("entry", description="Entry to check")]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._key = entry_key_of(self)
        self._sequence_id = 0
        self._still_running = False

    def tick(self) -> NodeStatus:
        child = self.child
        assert child is not None
        if self._still_running:
            status = child.execute_tick()
            self._still_running = status is RUNNING
            return status
        entry = self.config.blackboard.get_entry(self._key)
        if entry is None:
            return self._if_not_updated
        previous = self._sequence_id
        self._sequence_id = entry.sequence_id
        if previous == entry.sequence_id:
            return self._if_not_updated
        status = child.execute_tick()
        self._still_running = status is RUNNING
        return status

    def halt(self) -> None:
        self._still_running = False
        DecoratorNode.halt(self)


class SkipUnlessUpdatedNode(EntryUpdatedDecorator):
    """SKIPPED unless ``entry`` was updated."""

    _if_not_updated = SKIPPED


class WaitValueUpdateNode(EntryUpdatedDecorator):
    """RUNNING until ``entry`` is updated."""

    _if_not_updated = RUNNING


class LoopNode(DecoratorNode):
    """``LoopInt``/``LoopDouble``/...: pops one element of ``queue`` per iteration into ``value``."""

    item_type: Any = int

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            bidirectional_port(
                "queue", None, description="Vector or queue of values; a literal 'a;b;c' works too"
            ),
            input_port(
                "if_empty",
                NodeStatus,
                SUCCESS,
                "Status to return if queue is empty: SUCCESS, FAILURE, SKIPPED",
            ),
            output_port("value", cls.item_type),
        ]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._child_running = False
        self._queue: deque[Any] | None = None
        raw = self.config.input_ports.get("queue")
        self._static: list[Any] | None = None
        if isinstance(raw, str) and blackboard_pointer(raw, "queue") is None:
            self._static = convert_from_string(self._list_type(), raw, self.config.enums)

    def tick(self) -> NodeStatus:
        popped = False
        if self._status is IDLE:
            self._child_running = False
            self._queue = deque(self._static) if self._static is not None else None
        if not self._child_running:
            if self._static is None:
                self._read_queue()
            if self._queue:
                value = self._queue.popleft()
                popped = True
                self.set_output("value", value)
        if not popped and not self._child_running:
            return self.get_input("if_empty")
        if self._status is IDLE:
            _set_status_unchecked(self, RUNNING)
        assert self.child is not None
        status = self.child.execute_tick()
        self._child_running = status is RUNNING
        if status is SUCCESS or status is FAILURE:
            self.reset_child()
        if status is FAILURE:
            return FAILURE
        return RUNNING

    @classmethod
    def _list_type(cls) -> Any:
        return list[cls.item_type]  # type: ignore[name-defined]

    def _read_queue(self) -> None:
        key = self.port_blackboard_key("queue")
        if key is None:
            return
        entry = self.config.blackboard.get_entry(key)
        if entry is None or entry.value is None:
            return
        value = entry.value
        if isinstance(value, deque):
            self._queue = value  # a shared queue is popped in place
        elif self._queue is None:
            if isinstance(value, list | tuple):
                self._queue = deque(value)
            elif isinstance(value, str):
                self._queue = deque(convert_from_string(self._list_type(), value, self.config.enums))
            else:
                raise BTRuntimeError(
                    "LoopNode: port 'queue' must contain either a queue, a list, or a string"
                )


def make_loop(name: str, item_type: Any) -> type[LoopNode]:
    """The ``Loop<T>`` node class for one item type."""
    assert list_item_type(list[item_type]) is item_type
    return type(name, (LoopNode,), {"item_type": item_type, "__doc__": f"Loop over a queue of {name[4:]}."})


class SubTreeNode(DecoratorNode):
    """The root of a SubTree instance: ticks the subtree and returns its status.

    Attributes:
        subtree_id: the ID of the tree it instantiates.
    """

    __slots__ = ("subtree_id",)

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self.subtree_id = ""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "_autoremap", bool, False, "If true, all the ports with the same name will be remapped"
            )
        ]

    def tick(self) -> NodeStatus:
        # What the execute_tick below does inline, for nodes with conditions or callbacks.
        if self._status is IDLE:
            _set_status_unchecked(self, RUNNING)
        child = self.child
        assert child is not None
        status = child.execute_tick()
        if status is SUCCESS or status is FAILURE:
            self.reset_child()
        return status

    @inlines_tick
    def execute_tick(self) -> NodeStatus:
        # DecoratorNode.execute_tick fused with tick(), as in the result-mapping decorators.
        if self._hooked:
            return DecoratorNode.execute_tick(self)
        try:
            if self._status is IDLE:
                self._status = RUNNING
                if self._watched:
                    self._log.append(self._log_base + RUNNING)  # from IDLE, which is 0
            child = self.child
            assert child is not None
            status = child.execute_tick()
            if status is SUCCESS or status is FAILURE:
                done = child._status
                if done is RUNNING:
                    self.reset_child()
                else:
                    child._status = IDLE
                    if child._watched and done is not IDLE:
                        child._log.append(child._log_base + done * 5)  # IDLE is 0
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
        return status
