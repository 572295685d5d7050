"""Behaviors whose work runs off the tick thread (MoveIt Pro's ``AsyncBehaviorBase``)."""

from __future__ import annotations

import concurrent.futures
import inspect
import threading
from collections.abc import Awaitable
from typing import Any

from kinema.behaviors.base import Behavior
from kinema.behaviors.faults import BehaviorExecutionError, behavior_fault
from kinema.behaviors.work_runner import RUNNER
from kinema.bt import NodeStatus, StatefulActionNode


class AsyncBehavior(Behavior, StatefulActionNode):
    """A behavior that does slow work (I/O, planning, waiting) without stalling the tree.

    Override :meth:`do_work` (a coroutine function or a plain function) and, if the work holds
    resources, :meth:`do_halt`. While the work runs the node returns RUNNING; when it finishes the tree
    is woken and the node returns SUCCESS or FAILURE. Halting the node cancels the work: a coroutine is
    cancelled at its next ``await``; a plain function should check :meth:`stop_requested` regularly.
    """

    __slots__ = ("_future", "_pending_outputs", "_stop_event", "_tick_thread")

    def __init__(self, name: str, config: Any = None) -> None:
        super().__init__(name, config)
        self._future: concurrent.futures.Future[Any] | None = None
        self._stop_event = threading.Event()
        self._tick_thread = 0
        self._pending_outputs: list[tuple[str, Any]] = []

    def do_work(self) -> bool | Awaitable[bool]:
        """Do the work; return True for SUCCESS, False for FAILURE.

        Called once per start of the node, never on the tick thread: a plain function runs on a worker
        thread and may block as long as it needs; an ``async def`` runs on Kinema's asyncio loop and must
        ``await`` rather than block (a blocking call there stalls every other async behavior; wrap one in
        ``await asyncio.to_thread(...)``). It must not touch other nodes or the tree. Read inputs with
        ``get_input`` and write outputs with ``set_output`` (outputs written here reach the blackboard on
        the tick thread when the work finishes, so a running tree is only ever changed by its tick
        thread). For an expected failure call ``self.logger.publish_failure(...)`` and return False; an
        exception is treated as a bug and fails the objective with the line that raised.
        """
        raise NotImplementedError(f"{type(self).__name__}.do_work() is not implemented")

    def do_halt(self) -> None:
        """Release what :meth:`do_work` holds (cancel a goal, stop a motion).

        Called on the tick thread when the node is halted while its work runs, right before the work
        is cancelled. Must not block and must not raise.
        """

    def stop_requested(self) -> bool:
        """True once the node was halted; a plain-function ``do_work`` should return soon after."""
        return self._stop_event.is_set()

    def set_output(self, name: str, value: Any) -> None:
        """Write output port ``name``; from ``do_work`` the write is applied when the work finishes."""
        if self._tick_thread and threading.get_ident() != self._tick_thread:
            self._pending_outputs.append((name, value))
            return
        super().set_output(name, value)

    def on_start(self) -> NodeStatus:
        """Start :meth:`do_work` off the tick thread and return RUNNING (no need to override)."""
        self._stop_event = threading.Event()
        self._tick_thread = threading.get_ident()
        self._pending_outputs = []
        if inspect.iscoroutinefunction(self.do_work):
            future = RUNNER.run_coroutine(self._guarded(self.do_work()))  # type: ignore[arg-type]
        else:
            future = RUNNER.run_function(self.do_work)
        self._future = future
        future.add_done_callback(lambda _done: self.emit_wake_up_signal())
        return NodeStatus.RUNNING

    async def _guarded(self, work: Awaitable[bool]) -> bool:
        # asyncio lets SystemExit and KeyboardInterrupt out of the event loop, which would end it for
        # every async behavior of the process: they become this behavior's fault instead.
        import asyncio

        try:
            return await work
        except asyncio.CancelledError:
            raise
        except (KeyboardInterrupt, SystemExit) as error:
            raise behavior_fault(self, error, "do_work") from error

    def on_running(self) -> NodeStatus:
        """Return RUNNING until the work is done, then its outcome (no need to override)."""
        future = self._future
        if future is None or not future.done():
            return NodeStatus.RUNNING
        self._future = None
        if future.cancelled():
            return NodeStatus.FAILURE
        error = future.exception()
        if error is not None:
            fault = behavior_fault(self, error, "do_work")
            if fault is error:
                raise error
            raise fault from error
        outputs, self._pending_outputs = self._pending_outputs, []
        for name, value in outputs:
            super().set_output(name, value)
        result = future.result()
        if result is True:
            return NodeStatus.SUCCESS
        if result is False:
            return NodeStatus.FAILURE
        raise BehaviorExecutionError(
            f"behavior '{self.registration_id}': do_work() returned {result!r}; return True (success) "
            "or False (failure)"
        )

    def on_halted(self) -> None:
        """Ask the work to stop, call :meth:`do_halt`, cancel the work (no need to override)."""
        self._stop_event.set()
        future, self._future = self._future, None
        try:
            self.do_halt()
        except BaseException as error:
            # Halting must always complete (a cancel has to stop the tree), so a faulty do_halt is
            # reported as a failure toast naming the behavior, plugin and line, not raised.
            self.logger.publish_failure(str(behavior_fault(self, error, "do_halt")))
        finally:
            if future is not None and not future.cancel() and not future.done():
                # A plain function cannot be cancelled once it runs: the watchdog reports it while it
                # keeps running (it ignores stop_requested()).
                RUNNER.note_halted(future, str(self.registration_id), str(self.full_path))
