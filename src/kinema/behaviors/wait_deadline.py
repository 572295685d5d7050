"""A timeout for waiting on another party: it passes only once its seconds have passed on both clocks.

A behavior that waits for something another part of the cell produces (a service call, a message, a
frame) gives up after a timeout. In simulation the runtime's clock is sim time, which at ``--sim-speed
max`` runs many times faster than the wall clock while the agent plans, renders or solves: five seconds
of sim time can pass in the tenth of a second a planner takes, so a wait measured in sim time alone gives
up before the other party had a chance to answer (MoveIt Pro's "Record Square Trajectory" waits 5 s for
its start call while the other branch plans and makes a move). Measured in wall time alone, a simulation
slower than real time (a loaded machine) would give up before the robot had that long to move.
:class:`WaitDeadline` passes when both durations have passed, so at real time it is the plain timeout,
and faster or slower it is never shorter than either clock's.

Use it for waits on events; a duration the robot should spend (Sleep, the Timeout decorator, a tracking
window) stays in the runtime's clock alone.
"""

from __future__ import annotations

import math
import time
from typing import Any


class WaitDeadline:
    """Passes once ``seconds`` have passed on ``clock`` (the runtime's) and on the wall clock.

    Args:
        clock: the runtime's clock (``BehaviorContext.clock``): anything with ``now()`` in seconds.
        seconds: the timeout; negative or infinite means the deadline never passes.
    """

    def __init__(self, clock: Any, seconds: float) -> None:
        self._clock = clock
        self.seconds = float(seconds)
        self._clock_start = float(clock.now())
        self._wall_start = time.monotonic()

    @property
    def forever(self) -> bool:
        """True when the deadline never passes."""
        return self.seconds < 0 or math.isinf(self.seconds)

    def passed(self) -> bool:
        """True once the timeout has passed on both clocks."""
        if self.forever:
            return False
        return (
            float(self._clock.now()) - self._clock_start >= self.seconds
            and time.monotonic() - self._wall_start >= self.seconds
        )
