"""Built-in leaf nodes (reference §2.5)."""

from __future__ import annotations

from typing import Any

from kinema.bt.clock import WakeUpTimer
from kinema.bt.conversions import ConversionError, Unsigned, convert_from_string, has_converter, type_name
from kinema.bt.decorators import entry_key_of
from kinema.bt.errors import BTLogicError, BTRuntimeError, ScriptParseError
from kinema.bt.node import (
    ConditionNode,
    NodeConfig,
    PortError,
    StatefulActionNode,
    SyncActionNode,
    TreeNode,
    inlines_tick,
    script_bool,
)
from kinema.bt.ports import PortInfo, bidirectional_port, blackboard_pointer, input_port
from kinema.bt.script import Script, parse_script
from kinema.bt.status import FAILURE, RUNNING, SUCCESS, NodeStatus


class _ConstantNode(SyncActionNode):
    """A sync action that always returns ``_result``."""

    _result = SUCCESS

    def tick(self) -> NodeStatus:
        return self._result

    @inlines_tick
    def execute_tick(self) -> NodeStatus:
        # Same semantics as TreeNode.execute_tick without the call to tick(): these leaves are
        # the bulk of large trees, so one call less per node is measurable.
        if self._hooked:
            return self._execute_tick_hooked()
        result = self._result
        prev = self._status
        if prev is not result:
            self._status = result
            if self._watched:
                self._log.append(self._log_base + prev * 5 + result)
        return result


class AlwaysSuccessNode(_ConstantNode):
    """Returns SUCCESS."""

    _result = SUCCESS


class AlwaysFailureNode(_ConstantNode):
    """Returns FAILURE."""

    _result = FAILURE


class _ScriptCode:
    """The parsed ``code`` port shared by Script and ScriptCondition.

    A literal script is parsed once at construction; a ``{pointer}`` is re-parsed only when the
    text it points to changes. The tick stays in each node (it compares ``_code`` inline, so an
    unchanged script costs no extra call).
    """

    # A mixin: Script and ScriptCondition hold its state in slots of their own (__slots__ below).

    config: NodeConfig
    full_path: str
    registration_id: str
    _code: str
    _script: Script | None
    _literal: bool

    def _init_script(self) -> None:
        self._code = ""
        self._script = None
        raw = self.config.input_ports.get("code")
        if raw is None:
            # BT.CPP reads the port in the constructor: a Script without code fails createTree
            raise BTRuntimeError(f"Missing port [code] in {self.registration_id} '{self.full_path}'")
        # A literal script (not a {pointer}) is parsed now, once.
        self._literal = isinstance(raw, str) and blackboard_pointer(raw, "code") is None
        if self._literal and raw:
            self._load(raw)

    def _set_code(self, code: str) -> None:
        if code == "":
            self._script = None
            self._code = ""
        else:
            self._load(code)

    def _load(self, code: str) -> None:
        try:
            self._script = parse_script(code)
        except ScriptParseError as error:
            raise BTRuntimeError(
                f"Error in the script \"{code}\" of node '{self.full_path}': {error.message}"
            ) from None
        self._code = code


class ScriptNode(_ScriptCode, SyncActionNode):
    """Runs the ``code`` script and returns SUCCESS (an empty script does nothing)."""

    __slots__ = ("_code", "_literal", "_script")

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [input_port("code", str, description="Piece of code that can be parsed")]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._init_script()

    def tick(self) -> NodeStatus:
        # A literal code was parsed at construction; only a {pointer} is re-read every tick.
        if not self._literal:
            code = self.get_input("code", str)
            if code != self._code:
                self._set_code(code)
        script = self._script
        if script is not None:
            config = self.config
            script.run(config.blackboard, config.enums)
        return SUCCESS

    @inlines_tick
    def execute_tick(self) -> NodeStatus:
        # TreeNode.execute_tick fused with tick() for literal code on a node without conditions
        # or callbacks (nearly every Script): one call less per tick, same status and errors.
        script = self._script
        if self._hooked or not self._literal or script is None:
            return TreeNode.execute_tick(self)
        config = self.config
        try:
            single = script.single
            if single is not None:
                single(config.blackboard, config.enums)  # Script.run without its frame
            else:
                script.run(config.blackboard, config.enums)
        except Exception as error:
            failure = script.error(error)
            raise self._wrap_exception(failure) from failure
        prev = self._status
        if prev is not SUCCESS:
            self._status = SUCCESS
            if self._watched:
                self._log.append(self._log_base + prev * 5 + SUCCESS)
        return SUCCESS


class ScriptConditionNode(_ScriptCode, ConditionNode):
    """SUCCESS if the ``code`` script evaluates to true, else FAILURE."""

    __slots__ = ("_code", "_literal", "_script")

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "code", None, description="Piece of code that can be parsed. Must return false or true"
            )
        ]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._init_script()

    def tick(self) -> NodeStatus:
        # A literal code was parsed at construction; only a {pointer} is re-read every tick.
        if not self._literal:
            code = self.get_input("code", str)
            if code != self._code:
                self._set_code(code)
        script = self._script
        if script is None:
            raise BTRuntimeError(
                f"ScriptCondition '{self.full_path}' has an empty script (bad_function_call)"
            )
        config = self.config
        value = script.run(config.blackboard, config.enums)
        if value.__class__ is float:  # what comparisons return; script_bool's first case
            return SUCCESS if value != 0.0 else FAILURE
        return SUCCESS if script_bool(value) else FAILURE

    @inlines_tick
    def execute_tick(self) -> NodeStatus:
        # TreeNode.execute_tick fused with tick() for literal code on a node without conditions
        # or callbacks: one call less per tick, same status and errors.
        script = self._script
        if self._hooked or not self._literal or script is None:
            return TreeNode.execute_tick(self)
        config = self.config
        try:
            single = script.single
            try:
                # Script.run without its frame
                value = (
                    single(config.blackboard, config.enums)
                    if single is not None
                    else script.run(config.blackboard, config.enums)
                )
            except Exception as error:
                raise script.error(error) from None
            if value.__class__ is float:
                status = SUCCESS if value != 0.0 else FAILURE
            else:
                status = SUCCESS if script_bool(value) else FAILURE
        except Exception as error:
            raise self._wrap_exception(error) from error
        prev = self._status
        if prev is not status:
            self._status = status
            if self._watched:
                self._log.append(self._log_base + prev * 5 + status)
        return status


class SetBlackboardNode(SyncActionNode):
    """Copies ``value`` (a literal or ``{key}``) into the entry named by ``output_key``."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("value", None, description="Value to be written into the output_key"),
            bidirectional_port(
                "output_key",
                None,
                description="Name of the blackboard entry where the value should be written",
            ),
        ]

    def tick(self) -> NodeStatus:
        result = self.try_get_input("output_key", str)
        if not result.ok:
            raise BTRuntimeError("missing port [output_key]")
        output_key: str = result.value
        if "value" not in self.config.input_ports:
            raise BTRuntimeError(f"SetBlackboard '{self.full_path}': missing port [value]")
        value_str = self.config.input_ports["value"]
        bb = self.config.blackboard
        dst = bb.get_entry(output_key)
        source_key = blackboard_pointer(value_str, "value") if isinstance(value_str, str) else None
        if source_key is not None and value_str.strip() != "=":
            src = bb.get_entry(source_key)
            if src is None:
                raise BTRuntimeError("Can't find the port referred by [value]")
            if dst is None:
                dst = bb.create_entry(output_key, src.type)
            out_value: Any = src.value
        else:
            out_value = value_str
        if out_value is None:
            return FAILURE
        if dst is not None and dst.type is not str and isinstance(out_value, str):
            if has_converter(dst.type):
                try:
                    out_value = convert_from_string(dst.type, out_value, self.config.enums)
                except ConversionError as error:
                    raise BTLogicError(
                        f"Can't convert string [{out_value}] to type [{type_name(dst.type)}]: {error.message}"
                    ) from None
            else:
                # BT.CPP parses with the entry's (absent) converter and stores the resulting empty value.
                dst.value = None
                bb.notify_written(output_key, dst)
                return SUCCESS
        if dst is None:
            dst = bb.create_entry(output_key, _type_of_literal(out_value))
        bb.set(output_key, out_value)
        return SUCCESS


def _type_of_literal(value: Any) -> Any:
    return str if isinstance(value, str) else type(value)


class UnsetBlackboardNode(SyncActionNode):
    """Removes ``key`` from the local blackboard scope (never through ``@`` or remapping)."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [input_port("key", str, description="Key of the entry to remove")]

    def tick(self) -> NodeStatus:
        try:
            key = self.get_input("key")
        except PortError:
            raise BTRuntimeError("missing input port [key]") from None
        self.config.blackboard.unset(key)
        return SUCCESS


class SleepNode(StatefulActionNode):
    """RUNNING for ``msec`` milliseconds of the tree's clock, then SUCCESS."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [input_port("msec", Unsigned)]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._timer = WakeUpTimer(self, "SleepNode")

    def on_start(self) -> NodeStatus:
        try:
            msec = self.get_input("msec")
        except PortError:
            raise BTRuntimeError("Missing parameter [msec] in SleepNode") from None
        if msec <= 0:
            return SUCCESS
        self._timer.start(msec / 1000.0)
        return RUNNING

    def on_running(self) -> NodeStatus:
        if self._timer.fired.is_set():
            self._timer.cancel()
            return SUCCESS
        return RUNNING

    def on_halted(self) -> None:
        self._timer.cancel()


class WasEntryUpdatedNode(SyncActionNode):
    """SUCCESS if the ``entry`` blackboard key was written since this node last looked."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [input_port("entry", description="Entry to check")]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._key = entry_key_of(self)
        self._sequence_id = 0

    def tick(self) -> NodeStatus:
        entry = self.config.blackboard.get_entry(self._key)
        if entry is None:
            return FAILURE
        previous = self._sequence_id
        self._sequence_id = entry.sequence_id
        return SUCCESS if previous != entry.sequence_id else FAILURE
