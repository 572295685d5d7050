"""WaitForDuration: wait some seconds of runtime time (sim time in simulation)."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import NodeStatus, PortInfo, StatefulBehavior, input_port


class WaitForDuration(StatefulBehavior):
    """Returns RUNNING for ``delay_duration`` seconds of the runtime clock, then SUCCESS.

    In simulation the runtime clock is the simulator's, so the wait lasts the same in sim time at any
    sim speed. Halting it ends the wait at once.
    """

    subcategory = "Miscellaneous"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [input_port("delay_duration", float, 1.0, "Seconds to wait.")]

    def __init__(self, name: str, config: Any = None) -> None:
        super().__init__(name, config)
        self._deadline = 0.0
        self._timer: Any = None

    def on_start(self) -> NodeStatus:
        delay = float(self.get_input("delay_duration"))
        if delay < 0:
            self.logger.publish_failure(f"WaitForDuration: delay_duration must be >= 0, got {delay:g}")
            return NodeStatus.FAILURE
        clock = self.context.clock
        self._deadline = clock.now() + delay
        if delay == 0:
            return NodeStatus.SUCCESS
        self._timer = clock.call_later(delay, self.emit_wake_up_signal)
        return NodeStatus.RUNNING

    def on_running(self) -> NodeStatus:
        if self.context.clock.now() >= self._deadline:
            self._timer = None
            return NodeStatus.SUCCESS
        return NodeStatus.RUNNING

    def on_halted(self) -> None:
        timer, self._timer = self._timer, None
        if timer is not None:
            timer.cancel()
