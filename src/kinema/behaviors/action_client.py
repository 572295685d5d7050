"""Behaviors that send an action goal and act on its result (MoveIt Pro's ``ActionClientBehaviorBase``)."""

from __future__ import annotations

import concurrent.futures
import threading
from typing import TYPE_CHECKING, Any, ClassVar, Generic

from kinema.behaviors.asynchronous import AsyncBehavior
from kinema.behaviors.faults import BehaviorExecutionError, behavior_fault
from kinema.behaviors.interface_type import parametrize
from kinema.behaviors.work_runner import RUNNER
from kinema.errors import TransportError
from kinema.interfaces.definition import FeedbackT, GoalT, ResultT

if TYPE_CHECKING:
    import asyncio

    from kinema.transport import GoalResult


class ActionClientBehavior(AsyncBehavior, Generic[GoalT, ResultT, FeedbackT]):
    """Sends one goal per run: ``create_goal`` → feedback → ``process_result``.

    Derive from ``ActionClientBehavior[Fibonacci.Goal, Fibonacci.Result, Fibonacci.Feedback]`` (the
    interface's classes from ``kinema.interfaces.typed``, which types the hooks below), from
    ``ActionClientBehavior["pkg/action/Name"]`` (untyped), or set :attr:`action_type`; override
    :meth:`create_goal` and :meth:`process_result` (and :meth:`process_feedback` to follow progress);
    :meth:`get_action_name` reads the ``action_name`` port by default. Halting the node cancels the goal
    on the server. A rejected goal, a failed call or a result timeout publishes a failure toast and
    returns FAILURE.
    """

    __slots__ = ("_goal_handle",)

    action_type: ClassVar[str] = ""
    """The ROS action type, e.g. ``example_interfaces/action/Fibonacci``."""

    def __class_getitem__(cls, action_type: Any) -> Any:
        return parametrize(cls, "action_type", "action", action_type, ("Goal", "Result", "Feedback"))

    def __init__(self, name: str, config: Any = None) -> None:
        super().__init__(name, config)
        self._goal_handle: Any = None

    def get_action_name(self) -> str:
        """The action to call; default: the ``action_name`` input port. Called off the tick thread."""
        return str(self.get_input("action_name"))

    def create_goal(self) -> GoalT | dict[str, Any]:
        """Build the goal: a message or a dict of its fields. Called off the tick thread at each start."""
        raise NotImplementedError(f"{type(self).__name__}.create_goal() is not implemented")

    def process_feedback(self, feedback: FeedbackT) -> None:
        """Follow progress (e.g. ``set_output`` or a toast); default: ignore it.

        Called on a transport thread for each feedback message while the goal runs. Must not block. Feedback
        that reaches the client after the result is dropped, and a call in progress ends before
        :meth:`process_result` starts, so progress is never reported after the outcome.
        """

    def process_result(self, result: GoalResult[ResultT]) -> bool:
        """Act on the finished goal; return True for SUCCESS.

        ``result`` is a :class:`kinema.transport.GoalResult`: ``result.status``/``status_name``,
        ``result.succeeded`` and the result message ``result.result``. Called off the tick thread.
        """
        raise NotImplementedError(f"{type(self).__name__}.process_result() is not implemented")

    def get_result_timeout(self) -> float | None:
        """Seconds to wait for the result (None: as long as it takes); the goal is cancelled on timeout."""
        return None

    def do_halt(self) -> None:
        """Cancel the goal on the server (sent from a worker, so the tick thread never waits)."""
        handle, self._goal_handle = self._goal_handle, None
        if handle is not None and not handle.done():
            RUNNER.run_function(handle.cancel)

    async def do_work(self) -> bool:
        """Send the goal, wait for the result and process it (no need to override)."""
        import asyncio

        if not self.action_type:
            raise BehaviorExecutionError(
                f"behavior '{self.registration_id}' does not say which action type it calls; derive "
                "from ActionClientBehavior['pkg/action/Name'] or set action_type"
            )
        node = self.context.require_node(self.registration_id)
        name = self.get_action_name()
        goal = self.create_goal()
        client = self.context.action_client(node, self.action_type, name)
        loop = asyncio.get_running_loop()
        finished: asyncio.Future[None] = loop.create_future()
        feedback_errors: list[BaseException] = []
        # Feedback travels apart from the result and can be dispatched after it: once the result is in,
        # late feedback is dropped, so process_feedback never reports progress after the outcome. The lock
        # also lets a feedback call in progress finish before the result is processed.
        feedback_lock = threading.Lock()
        result_in = False

        def on_feedback(feedback: Any) -> None:
            with feedback_lock:
                if result_in:
                    return
                try:
                    self.process_feedback(feedback)
                except Exception as error:
                    feedback_errors.append(error)

        def on_done(_handle: Any) -> None:
            nonlocal result_in
            with feedback_lock:
                result_in = True
            loop.call_soon_threadsafe(_resolve, finished)

        sending = RUNNER.run_function(lambda: client.send_goal(goal, on_feedback, timeout=10.0))
        try:
            handle = await asyncio.shield(asyncio.wrap_future(sending))
        except asyncio.CancelledError:
            # Halted while the goal was on its way: cancel it as soon as the server has accepted it.
            sending.add_done_callback(_cancel_when_accepted)
            raise
        except TransportError as error:
            self.logger.publish_failure(f"Failed to send a goal to {name}: {error}")
            return False
        if not handle.accepted:
            self.logger.publish_failure(f"The goal was rejected by {name}")
            return False
        self._goal_handle = handle
        handle.add_done_callback(on_done)
        try:
            await asyncio.wait_for(finished, self.get_result_timeout())
        except TimeoutError:
            self.logger.publish_failure(f"No result from {name} within {self.get_result_timeout():g} s")
            RUNNER.run_function(handle.cancel)
            return False
        except asyncio.CancelledError:
            if not handle.done():
                RUNNER.run_function(handle.cancel)
            raise
        finally:
            self._goal_handle = None
        if feedback_errors:
            raise behavior_fault(self, feedback_errors[0], "process_feedback")
        try:
            outcome = handle.result(0)
        except TransportError as error:
            self.logger.publish_failure(f"Goal on {name} failed: {error}")
            return False
        try:
            return self.process_result(outcome)
        except Exception as error:
            raise behavior_fault(self, error, "process_result") from error


def _cancel_when_accepted(sending: concurrent.futures.Future[Any]) -> None:
    if sending.cancelled() or sending.exception() is not None:
        return
    handle = sending.result()
    if handle.accepted and not handle.done():
        RUNNER.run_function(handle.cancel)


def _resolve(future: asyncio.Future[None]) -> None:
    if not future.done():
        future.set_result(None)
