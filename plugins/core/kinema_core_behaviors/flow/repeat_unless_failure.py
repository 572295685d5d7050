"""RepeatUnlessFailureEachTick and RepeatUnlessFailureWithinTick: run the child until it fails.

Both count the child's successes and succeed after ``num_cycles`` of them (-1: never, the loop ends only
when the child fails); a child failure ends the loop with FAILURE at once. They differ in where an
iteration that completes within one tick leaves the tick thread:

- **EachTick** returns RUNNING after every successful iteration and starts the next one on the next tick
  of the tree (the runtime's next tick period), without asking for an immediate re-tick. A loop of
  instant children therefore takes one tick per iteration and never holds the tick thread; halts and
  cancels are served between iterations.
- **WithinTick** runs the iterations back to back in the same tick as long as the child completes
  synchronously, and returns RUNNING only while the child is RUNNING. A fixed number of instant
  iterations (building a list of candidates, say) finishes in one tick. A loop that runs longer than
  :data:`WITHIN_TICK_BUDGET_S` in one tick (``num_cycles="-1"`` over a child that always succeeds at once)
  returns RUNNING with a wake-up signal and goes on at once, as BT.CPP's Repeat does after each
  iteration: the objective server can then serve a cancel between two iterations (DESIGN invariant 2),
  where MoveIt Pro's loop would hold its tick thread for good.

BT.CPP 4.8.2's Repeat sits between the two: after a synchronous success it returns RUNNING *and* emits a
wake-up signal, so the tree is ticked again at once (``tick_once`` keeps re-ticking), while after a child
that was RUNNING it starts the next iteration within the same tick. A child returning SKIPPED makes both
return SKIPPED, as Repeat does, and forget the count (Repeat keeps it).
"""

from __future__ import annotations

import time
from typing import Any, ClassVar

from kinema.behaviors import NodeStatus, PortInfo, input_port
from kinema.behaviors.base import Behavior
from kinema.bt import DecoratorNode
from kinema.bt.errors import BTLogicError

from ..messages.ports import fails_on_bad_input, port_error, read_input

# How long RepeatUnlessFailureWithinTick loops in one tick before it lets the tick end (and asks for the next
# one at once): long enough for thousands of instant iterations, short against a cancel.
WITHIN_TICK_BUDGET_S = 0.02

IDLE, RUNNING, SUCCESS, FAILURE, SKIPPED = (
    NodeStatus.IDLE,
    NodeStatus.RUNNING,
    NodeStatus.SUCCESS,
    NodeStatus.FAILURE,
    NodeStatus.SKIPPED,
)


class _RepeatUnlessFailure(Behavior, DecoratorNode):
    """The shared loop; :attr:`within_tick` says whether iterations continue in the same tick."""

    subcategory = "Miscellaneous"
    within_tick: ClassVar[bool] = False

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "num_cycles",
                int,
                description="Successes after which the loop succeeds; -1 repeats until the child fails.",
            )
        ]

    def __init__(self, name: str, config: Any = None) -> None:
        DecoratorNode.__init__(self, name, config)
        self._count = 0

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        cycles = int(read_input(self, "num_cycles"))
        if cycles < -1:
            raise port_error(
                self, "num_cycles", f"= {cycles}", "give a count >= 0, or -1 to loop until failure"
            )
        child = self.child
        assert child is not None
        deadline = time.monotonic() + WITHIN_TICK_BUDGET_S
        while cycles == -1 or self._count < cycles:
            if self.within_tick and child.status is IDLE and time.monotonic() > deadline:
                self.emit_wake_up_signal()
                return RUNNING
            status = child.execute_tick()
            if status is RUNNING:
                return RUNNING
            self.reset_child()
            if status is FAILURE or status is SKIPPED:
                self._count = 0
                return status
            if status is not SUCCESS:
                raise BTLogicError(f"[{self.name}]: A children should not return IDLE")
            self._count += 1
            if not self.within_tick and (cycles == -1 or self._count < cycles):
                return RUNNING
        self._count = 0
        return SUCCESS

    def halt(self) -> None:
        self._count = 0
        DecoratorNode.halt(self)


class RepeatUnlessFailureEachTick(_RepeatUnlessFailure):
    """Runs the child until it fails (FAILURE) or has succeeded ``num_cycles`` times (SUCCESS), one
    iteration per tick.

    After each success it returns RUNNING and starts the next iteration on the next tick, so even an
    endless loop (``num_cycles="-1"``) of instant children never holds the tick thread. Unlike BT.CPP's
    Repeat it asks for no immediate re-tick. Inverted on both sides it retries a failing child up to
    ``num_cycles`` times.
    """


class RepeatUnlessFailureWithinTick(_RepeatUnlessFailure):
    """Runs the child until it fails (FAILURE) or has succeeded ``num_cycles`` times (SUCCESS), back to
    back in one tick while the child completes at once.

    It returns RUNNING while the child is RUNNING (the next iteration then follows in the tick that
    completes it). Unlike BT.CPP's Repeat it does not yield between instant iterations, so ``num_cycles``
    instant iterations take one tick; only a loop still going after :data:`WITHIN_TICK_BUDGET_S` returns
    RUNNING and is ticked again at once, so that a cancel is served (see the module docstring).
    """

    within_tick = True
