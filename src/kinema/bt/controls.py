"""Built-in control nodes with BT.CPP 4.10's exact algorithms (reference §2.3)."""

from __future__ import annotations

from kinema.bt.conversions import FLT_EPSILON, parse_double_full, parse_int_full
from kinema.bt.errors import BTLogicError, BTRuntimeError, NodeExecutionError
from kinema.bt.node import (
    ControlNode,
    NodeConfig,
    PortError,
    _set_status_unchecked,
    inlines_tick,
)
from kinema.bt.ports import PortInfo, input_port
from kinema.bt.status import FAILURE, IDLE, RUNNING, SKIPPED, SUCCESS, NodeStatus


def _idle_child(node: ControlNode) -> BTLogicError:
    return BTLogicError(f"[{node.name}]: A children should not return IDLE")


class _ResumingControl(ControlNode):
    """State of Sequence and Fallback: the child to resume at and how many children were skipped.

    Halting starts over from the first child (SequenceWithMemory keeps its index and is not one).
    """

    # Slots, as for the node state of every built-in: no instance dict to allocate per node, and the
    # tick reads them as slots.
    __slots__ = ("_idx", "_skipped")

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._idx = 0
        self._skipped = 0

    def halt(self) -> None:
        self._idx = 0
        self._skipped = 0
        ControlNode.halt(self)


class SequenceNode(_ResumingControl):
    """Ticks children in order; remembers the running child; FAILURE restarts from the first.

    The async variant yields (wake-up + RUNNING) after each child that succeeds from IDLE.
    """

    _asynch = False

    def tick(self) -> NodeStatus:
        return SequenceNode.execute_tick(self, False)  # plain=False: the caller stores the status

    @inlines_tick
    def execute_tick(self, plain: bool = True) -> NodeStatus:
        # Fused with TreeNode.execute_tick (one Python frame per Sequence instead of two); tick(), the
        # hooked path's entry, runs the same body with plain=False, which leaves the status to it.
        if plain and self._hooked:
            return self._execute_tick_hooked()
        try:
            children = self.children
            n = len(children)
            if self._status is not RUNNING:
                if self._status is IDLE:
                    self._skipped = 0
                was = self._status
                self._status = RUNNING
                if self._watched:
                    self._log.append(self._log_base + was * 5 + RUNNING)
            idx = self._idx
            if self._asynch:
                status = self._tick_async(children, n, idx)
            else:
                # The plain Sequence's hot loop (the async one is the same plus a yield after each success).
                for child in children if idx == 0 else children[idx:]:
                    try:
                        status = child.execute_tick()
                    except BaseException:
                        # BT.CPP advances its member index in place: an exception that escapes a child
                        # leaves it on that child, and the next tick resumes there.
                        self._idx = idx
                        raise
                    if status is SUCCESS:
                        idx += 1
                    elif status is RUNNING:
                        self._idx = idx
                        break
                    elif status is FAILURE:
                        self.reset_children()
                        self._idx = 0
                        break
                    elif status is SKIPPED:
                        idx += 1
                        self._skipped += 1
                    else:
                        self._idx = idx
                        raise _idle_child(self)
                else:
                    status = self._finish(n)
        except NodeExecutionError:
            raise
        except Exception as error:
            raise self._wrap_exception(error) from error
        if plain:
            prev = self._status
            if status is not prev:
                if status is SUCCESS or status is FAILURE:
                    self._status = status
                    if self._watched:
                        self._log.append(self._log_base + prev * 5 + status)
                elif status is not SKIPPED:
                    self._set_status(status)
            elif status is IDLE:
                self._set_status(status)
        return status

    def _tick_async(self, children: list, n: int, idx: int) -> NodeStatus:
        while idx < n:
            child = children[idx]
            prev = child._status
            try:
                status = child.execute_tick()
            except BaseException:
                self._idx = idx  # as in the plain loop
                raise
            if status is SUCCESS:
                idx += 1
                if prev is IDLE and idx < n:
                    self._idx = idx
                    self.emit_wake_up_signal()
                    return RUNNING
                continue
            if status is RUNNING:
                self._idx = idx
                return RUNNING
            if status is FAILURE:
                self.reset_children()
                self._idx = 0
                return FAILURE
            if status is SKIPPED:
                idx += 1
                self._skipped += 1
            else:
                self._idx = idx
                raise _idle_child(self)
        return self._finish(n)

    def _finish(self, n: int) -> NodeStatus:
        all_skipped = self._skipped == n
        self.reset_children()
        self._idx = 0
        self._skipped = 0
        return SKIPPED if all_skipped else SUCCESS


class AsyncSequenceNode(SequenceNode):
    """Sequence that yields to the tree after every child that succeeds from IDLE."""

    _asynch = True


class SequenceWithMemoryNode(ControlNode):
    """Sequence that does not restart after FAILURE: the next tick resumes at the failed child."""

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._idx = 0
        self._skipped = 0

    def tick(self) -> NodeStatus:
        children = self.children
        n = len(children)
        if self._status is not RUNNING:
            if self._status is IDLE:
                self._skipped = 0
            was = self._status
            self._status = RUNNING
            if self._watched:
                self._log.append(self._log_base + was * 5 + RUNNING)
        while self._idx < n:
            child = children[self._idx]
            prev = child._status
            status = child.execute_tick()
            if status is RUNNING:
                return RUNNING
            if status is FAILURE:
                for i in range(self._idx, n):
                    self.halt_child(i)
                return FAILURE
            if status is SUCCESS:
                self._idx += 1
                if prev is IDLE and self._idx < n:
                    self.emit_wake_up_signal()
                    return RUNNING
            elif status is SKIPPED:
                self._idx += 1
                self._skipped += 1
            else:
                raise _idle_child(self)
        all_skipped = self._skipped == n
        self.reset_children()
        self._idx = 0
        self._skipped = 0
        return SKIPPED if all_skipped else SUCCESS


class FallbackNode(_ResumingControl):
    """Ticks children in order until one succeeds (the mirror of Sequence).

    The async variant yields (wake-up + RUNNING) after each child that fails from IDLE.
    """

    _asynch = False

    def tick(self) -> NodeStatus:
        return FallbackNode.execute_tick(self, False)  # plain=False: the caller stores the status

    @inlines_tick
    def execute_tick(self, plain: bool = True) -> NodeStatus:
        # Fused with TreeNode.execute_tick, as SequenceNode's.
        if plain and self._hooked:
            return self._execute_tick_hooked()
        try:
            children = self.children
            n = len(children)
            if self._status is not RUNNING:
                if self._status is IDLE:
                    self._skipped = 0
                was = self._status
                self._status = RUNNING
                if self._watched:
                    self._log.append(self._log_base + was * 5 + RUNNING)
            idx = self._idx
            if self._asynch:
                status = self._tick_async(children, n, idx)
            else:
                # The plain Fallback's hot loop (the async one is the same plus a yield after each failure).
                for child in children if idx == 0 else children[idx:]:
                    try:
                        status = child.execute_tick()
                    except BaseException:
                        # BT.CPP advances its member index in place: an exception that escapes a child
                        # leaves it on that child, and the next tick resumes there.
                        self._idx = idx
                        raise
                    if status is FAILURE:
                        idx += 1
                    elif status is RUNNING:
                        self._idx = idx
                        break
                    elif status is SUCCESS:
                        self.reset_children()
                        self._idx = 0
                        break
                    elif status is SKIPPED:
                        idx += 1
                        self._skipped += 1
                    else:
                        self._idx = idx
                        raise _idle_child(self)
                else:
                    status = self._finish(n)
        except NodeExecutionError:
            raise
        except Exception as error:
            raise self._wrap_exception(error) from error
        if plain:
            prev = self._status
            if status is not prev:
                if status is SUCCESS or status is FAILURE:
                    self._status = status
                    if self._watched:
                        self._log.append(self._log_base + prev * 5 + status)
                elif status is not SKIPPED:
                    self._set_status(status)
            elif status is IDLE:
                self._set_status(status)
        return status

    def _tick_async(self, children: list, n: int, idx: int) -> NodeStatus:
        while idx < n:
            child = children[idx]
            prev = child._status
            try:
                status = child.execute_tick()
            except BaseException:
                self._idx = idx  # as in the plain loop
                raise
            if status is FAILURE:
                idx += 1
                if prev is IDLE and idx < n:
                    self._idx = idx
                    self.emit_wake_up_signal()
                    return RUNNING
            elif status is RUNNING:
                self._idx = idx
                return RUNNING
            elif status is SUCCESS:
                self.reset_children()
                self._idx = 0
                return SUCCESS
            elif status is SKIPPED:
                idx += 1
                self._skipped += 1
            else:
                self._idx = idx
                raise _idle_child(self)
        return self._finish(n)

    def _finish(self, n: int) -> NodeStatus:
        all_skipped = self._skipped == n
        self.reset_children()
        self._idx = 0
        self._skipped = 0
        return SKIPPED if all_skipped else FAILURE


class AsyncFallbackNode(FallbackNode):
    """Fallback that yields to the tree after every child that fails from IDLE."""

    _asynch = True


class _RunningChildControl(ControlNode):
    """State of ReactiveSequence, ReactiveFallback and Switch: the index of a child that went
    RUNNING (-1: none); halting forgets it."""

    __slots__ = ("_running_child",)

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._running_child = -1

    def halt(self) -> None:
        self._running_child = -1
        ControlNode.halt(self)


class ReactiveSequenceNode(_RunningChildControl):
    """Re-ticks every child from the first on every tick; a RUNNING child halts all the others."""

    def tick(self) -> NodeStatus:
        return ReactiveSequenceNode.execute_tick(self, False)  # plain=False: the caller stores the status

    @inlines_tick
    def execute_tick(self, plain: bool = True) -> NodeStatus:
        # Fused with TreeNode.execute_tick, as SequenceNode's.
        if plain and self._hooked:
            return self._execute_tick_hooked()
        try:
            all_skipped = True
            prev = self._status
            if prev is not RUNNING:
                if prev is IDLE:
                    self._running_child = -1
                was = self._status
                self._status = RUNNING
                if self._watched:
                    self._log.append(self._log_base + was * 5 + RUNNING)
            children = self.children
            index = -1
            for child in children:
                index += 1
                status = child.execute_tick()
                if status is SUCCESS:
                    all_skipped = False
                    continue
                if status is SKIPPED:
                    self.halt_child(index)
                    continue
                all_skipped = False
                if status is RUNNING:
                    for i in range(len(children)):
                        if i != index:
                            self.halt_child(i)
                    if self._running_child == -1:
                        self._running_child = index
                    break
                if status is FAILURE:
                    self.reset_children()
                    break
                raise _idle_child(self)
            else:
                # reset_children() inlined: after a pass that succeeded no child is RUNNING
                for child in children:
                    if child._status is not IDLE:
                        if child._status is RUNNING or child._watched:
                            self.reset_children()
                            break
                        child._status = IDLE
                status = SKIPPED if all_skipped else SUCCESS
        except NodeExecutionError:
            raise
        except Exception as error:
            raise self._wrap_exception(error) from error
        if plain:
            prev = self._status
            if status is not prev:
                if status is SUCCESS or status is FAILURE:
                    self._status = status
                    if self._watched:
                        self._log.append(self._log_base + prev * 5 + status)
                elif status is not SKIPPED:
                    self._set_status(status)
            elif status is IDLE:
                self._set_status(status)
        return status


class ReactiveFallbackNode(_RunningChildControl):
    """Re-ticks every child from the first on every tick until one succeeds."""

    def tick(self) -> NodeStatus:
        all_skipped = True
        if self._status is IDLE:
            self._running_child = -1
        if self._status is not RUNNING:
            _set_status_unchecked(self, RUNNING)
        children = self.children
        for index, child in enumerate(children):
            status = child.execute_tick()
            if status is not SKIPPED:
                all_skipped = False
            if status is RUNNING:
                for i in range(len(children)):
                    if i != index:
                        self.halt_child(i)
                if self._running_child == -1:
                    self._running_child = index
                return RUNNING
            if status is SUCCESS:
                self.reset_children()
                return SUCCESS
            if status is SKIPPED:
                self.halt_child(index)
            elif status is not FAILURE:
                raise _idle_child(self)
        self.reset_children()
        return SKIPPED if all_skipped else FAILURE


def _threshold(value: int, n: int) -> int:
    return max(n + value + 1, 0) if value < 0 else value


class ParallelNode(ControlNode):
    """Ticks all children; succeeds when ``success_count`` succeeded, fails when ``failure_count`` failed."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "success_count", int, -1, "number of children that need to succeed to trigger a SUCCESS"
            ),
            input_port("failure_count", int, 1, "number of children that need to fail to trigger a FAILURE"),
        ]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._completed: set[int] = set()
        self._success = 0
        self._failure = 0

    def _clear(self) -> None:
        self._completed.clear()
        self._success = 0
        self._failure = 0

    def tick(self) -> NodeStatus:
        try:
            success_count = self.get_input("success_count")
            failure_count = self.get_input("failure_count")
        except PortError as error:
            raise BTRuntimeError(
                f"Missing parameter [success_count/failure_count] in ParallelNode: {error.message}"
            ) from None
        n = len(self.children)
        success_threshold = _threshold(success_count, n)
        failure_threshold = _threshold(failure_count, n)
        if n < success_threshold:
            raise BTLogicError("Number of children is less than threshold. Can never succeed.")
        if n < failure_threshold:
            raise BTLogicError("Number of children is less than threshold. Can never fail.")
        _set_status_unchecked(self, RUNNING)
        skipped = 0
        for i, child in enumerate(self.children):
            if i not in self._completed:
                status = child.execute_tick()
                if status is SKIPPED:
                    skipped += 1
                elif status is SUCCESS:
                    self._completed.add(i)
                    self._success += 1
                elif status is FAILURE:
                    self._completed.add(i)
                    self._failure += 1
                elif status is not RUNNING:
                    raise _idle_child(self)
            if self._success >= success_threshold or (
                success_count < 0 and self._success + skipped >= success_threshold
            ):
                self._clear()
                self.reset_children()
                return SUCCESS
            if n - self._failure < success_threshold or self._failure == failure_threshold:
                self._clear()
                self.reset_children()
                return FAILURE
        return SKIPPED if skipped == n else RUNNING

    def halt(self) -> None:
        self._clear()
        ControlNode.halt(self)


class ParallelAllNode(ControlNode):
    """Ticks every child until all completed; FAILURE if at least ``max_failures`` failed."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "max_failures",
                int,
                1,
                "If the number of children returning FAILURE exceeds this value, ParallelAll returns FAILURE",
            )
        ]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._completed: set[int] = set()
        self._failures = 0

    def tick(self) -> NodeStatus:
        try:
            max_failures = self.get_input("max_failures")
        except PortError:
            raise BTRuntimeError("Missing parameter [max_failures] in ParallelNode") from None
        n = len(self.children)
        threshold = _threshold(max_failures, n)
        if n < threshold:
            raise BTLogicError("Number of children is less than threshold. Can never fail.")
        _set_status_unchecked(self, RUNNING)
        skipped = 0
        for i, child in enumerate(self.children):
            if i in self._completed:
                continue
            status = child.execute_tick()
            if status is SUCCESS:
                self._completed.add(i)
            elif status is FAILURE:
                self._completed.add(i)
                self._failures += 1
            elif status is SKIPPED:
                skipped += 1
            elif status is not RUNNING:
                raise _idle_child(self)
        if skipped == n:
            return SKIPPED
        if skipped + len(self._completed) >= n:
            self.halt_children()
            self._completed.clear()
            result = FAILURE if self._failures >= threshold else SUCCESS
            self._failures = 0
            return result
        return RUNNING

    def halt(self) -> None:
        self._completed.clear()
        self._failures = 0
        ControlNode.halt(self)


class IfThenElseNode(ControlNode):
    """``if child0 then child1 [else child2]``; the condition is not re-checked while a branch runs."""

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._child_idx = 0

    def tick(self) -> NodeStatus:
        n = len(self.children)
        if n != 2 and n != 3:
            raise BTLogicError("IfThenElseNode must have either 2 or 3 children")
        _set_status_unchecked(self, RUNNING)
        if self._child_idx == 0:
            condition = self.children[0].execute_tick()
            if condition is RUNNING:
                return RUNNING
            if condition is SUCCESS:
                self._child_idx = 1
            elif condition is FAILURE:
                if n == 3:
                    self._child_idx = 2
                else:
                    return condition
        if self._child_idx > 0:
            status = self.children[self._child_idx].execute_tick()
            if status is RUNNING:
                return RUNNING
            self.reset_children()
            self._child_idx = 0
            return status
        raise BTLogicError("Something unexpected happened in IfThenElseNode")

    def halt(self) -> None:
        self._child_idx = 0
        ControlNode.halt(self)


class WhileDoElseNode(ControlNode):
    """Reactive ``while child0 do child1 [else child2]``: the condition is re-ticked every tick."""

    def tick(self) -> NodeStatus:
        n = len(self.children)
        if n != 2 and n != 3:
            raise BTLogicError("WhileDoElseNode must have either 2 or 3 children")
        _set_status_unchecked(self, RUNNING)
        condition = self.children[0].execute_tick()
        if condition is RUNNING:
            return RUNNING
        status = IDLE
        if condition is SUCCESS:
            if n == 3:
                self.halt_child(2)
            status = self.children[1].execute_tick()
        elif condition is FAILURE:
            if n == 3:
                self.halt_child(1)
                status = self.children[2].execute_tick()
            else:
                status = FAILURE
        if status is RUNNING:
            return RUNNING
        self.reset_children()
        return status


def check_string_equality(a: str, b: str, enums: dict[str, int] | None) -> bool:
    """Switch's case comparison: equal text, else equal ints, else doubles within FLT_EPSILON.

    Both sides must be consumed completely (``"5abc"`` does not match ``"5"``); a registered
    scripting enum name stands for its value.
    """
    if a == b:
        return True

    def as_int(text: str) -> int | None:
        if enums and text in enums:
            return enums[text]
        return parse_int_full(text)

    ia, ib = as_int(a), as_int(b)
    if ia is not None and ib is not None and ia == ib:
        return True

    def as_double(text: str) -> float | None:
        if enums and text in enums:
            return float(enums[text])
        return parse_double_full(text)

    da, db = as_double(a), as_double(b)
    return da is not None and db is not None and abs(da - db) <= FLT_EPSILON


class SwitchNode(_RunningChildControl):
    """``SwitchN``: ticks the child whose ``case_i`` equals ``variable``, else the last (default) child."""

    cases = 2

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        ports = [input_port("variable", str)]
        ports += [input_port(f"case_{i}", str) for i in range(1, cls.cases + 1)]
        return ports

    def tick(self) -> NodeStatus:
        n_cases = self.cases
        if len(self.children) != n_cases + 1:
            raise BTLogicError("Wrong number of children in SwitchNode; must be (num_cases + default)")
        match = n_cases
        variable = self.try_get_input("variable", str)
        if variable.ok:
            for i in range(n_cases):
                case = self.try_get_input(f"case_{i + 1}", str)
                if case.ok and check_string_equality(variable.value, case.value, self.config.enums):
                    match = i
                    break
        if self._running_child != -1 and self._running_child != match:
            self.halt_child(self._running_child)
        status = self.children[match].execute_tick()
        if status is SKIPPED:
            self._running_child = -1
            return SKIPPED
        if status is RUNNING:
            self._running_child = match
        else:
            self.reset_children()
            self._running_child = -1
        return status


def make_switch(n: int) -> type[SwitchNode]:
    """The ``Switch<n>`` node class."""
    return type(f"Switch{n}", (SwitchNode,), {"cases": n, "__doc__": f"Switch with {n} cases and a default."})


class TryCatchNode(ControlNode):
    """Children 0..n-2 run as a sequence; on FAILURE the last child (catch) runs and TryCatch fails."""

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "catch_on_halt",
                bool,
                False,
                "If true, the catch child is also executed when the TryCatch node is halted",
            )
        ]

    def __init__(self, name: str, config: NodeConfig | None = None) -> None:
        super().__init__(name, config)
        self._idx = 0
        self._skipped = 0
        self._in_catch = False

    def tick(self) -> NodeStatus:
        n = len(self.children)
        if n < 2:
            raise BTLogicError(f"[{self.name}]: TryCatch requires at least 2 children")
        if self._status is not RUNNING:
            if self._status is IDLE:
                self._skipped = 0
            self._in_catch = False
        _set_status_unchecked(self, RUNNING)
        try_count = n - 1
        while True:
            if self._in_catch:
                status = self.children[-1].execute_tick()
                if status is RUNNING:
                    return RUNNING
                self.reset_children()
                self._idx = 0
                self._in_catch = False
                return FAILURE
            while self._idx < try_count:
                status = self.children[self._idx].execute_tick()
                if status is RUNNING:
                    return RUNNING
                if status is FAILURE:
                    self.reset_children()
                    self._idx = 0
                    self._in_catch = True
                    break
                if status is SUCCESS:
                    self._idx += 1
                elif status is SKIPPED:
                    self._idx += 1
                    self._skipped += 1
                else:
                    raise BTLogicError(f"[{self.name}]: A child should not return IDLE")
            else:
                all_skipped = self._skipped == try_count
                self.reset_children()
                self._idx = 0
                self._skipped = 0
                return SKIPPED if all_skipped else SUCCESS

    def halt(self) -> None:
        catch_on_halt = self.get_input_or("catch_on_halt", False)
        if catch_on_halt and not self._in_catch and self._status.is_active and len(self.children) >= 2:
            for i in range(len(self.children) - 1):
                self.halt_child(i)
            status = self.children[-1].execute_tick()
            if status is RUNNING:
                self.halt_child(len(self.children) - 1)
        self._idx = 0
        self._skipped = 0
        self._in_catch = False
        ControlNode.halt(self)
