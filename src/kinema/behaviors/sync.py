"""Behaviors that finish within one tick, and behaviors that run over several ticks on the tick thread."""

from __future__ import annotations

from kinema.behaviors.base import Behavior
from kinema.bt import NodeStatus, StatefulActionNode, SyncActionNode


class SyncBehavior(Behavior, SyncActionNode):
    """A behavior whose work is done in one call of :meth:`tick` (MoveIt Pro's ``SyncActionNode``).

    Override :meth:`tick`. Use it for quick computations: reading and writing ports, math, checks.
    """

    __slots__ = ()

    def tick(self) -> NodeStatus:
        """Do the work and return SUCCESS or FAILURE.

        Called on the tick thread each time the node is ticked. Must return quickly (the whole tree
        waits for it) and must never return RUNNING; use :class:`AsyncBehavior` for slow work. Return
        FAILURE (after ``self.logger.publish_failure(...)``) for an expected failure; an exception means a
        bug and fails the objective.
        """
        raise NotImplementedError(f"{type(self).__name__}.tick() is not implemented")


class StatefulBehavior(Behavior, StatefulActionNode):
    """A behavior that runs over several ticks without a thread (MoveIt Pro's ``StatefulActionNode``).

    Override :meth:`on_start`, :meth:`on_running` and :meth:`on_halted`. Use it to poll something
    that progresses on its own (a timer, a state published by another process).
    """

    __slots__ = ()

    def on_start(self) -> NodeStatus:
        """Start the work; return RUNNING to be polled, or SUCCESS/FAILURE if already done.

        Called on the tick thread when the node is ticked while idle. Must not block.
        """
        raise NotImplementedError(f"{type(self).__name__}.on_start() is not implemented")

    def on_running(self) -> NodeStatus:
        """Check progress; return RUNNING, SUCCESS or FAILURE.

        Called on the tick thread on every tick while the node is RUNNING. Must not block.
        """
        raise NotImplementedError(f"{type(self).__name__}.on_running() is not implemented")

    def on_halted(self) -> None:
        """Stop the work; called on the tick thread when the node is halted while RUNNING.

        Must not block and must not raise; it is called when the objective is cancelled or a parent
        no longer needs the result.
        """
