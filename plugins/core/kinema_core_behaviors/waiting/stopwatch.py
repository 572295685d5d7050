"""StopwatchBegin and StopwatchEnd: measure how long part of an objective takes, in runtime time."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from ..messages.ports import fails_on_bad_input, read_input, write_output


class StopwatchBegin(SyncBehavior):
    """Writes the current time of the runtime clock to ``timepoint`` and succeeds.

    The time is seconds on the runtime clock: sim time in simulation, so a measured cycle time does not
    depend on how fast the simulation runs. Pair it with a StopwatchEnd reading the same entry.
    """

    subcategory = "Miscellaneous"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            output_port(
                "timepoint",
                float,
                "{timepoint}",
                "The time it ran (s on the runtime clock: sim time in simulation), for StopwatchEnd.",
            )
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        write_output(self, "timepoint", float(self.context.clock.now()))
        return NodeStatus.SUCCESS


class StopwatchEnd(SyncBehavior):
    """Shows the seconds elapsed since the StopwatchBegin that wrote ``timepoint``, as an info message.

    It succeeds whenever ``timepoint`` holds a time; it fails when no StopwatchBegin has written it.
    The elapsed time is also written to ``elapsed_duration`` when the objective sets that port (an
    addition of Kinema's: MoveIt Pro's objectives only read the log), so a later step can use it.
    """

    subcategory = "Miscellaneous"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("timepoint", float, "{timepoint}", "The time StopwatchBegin wrote."),
            output_port(
                "elapsed_duration",
                float,
                description=(
                    "Optional (Kinema): the seconds elapsed on the runtime clock; written only when set."
                ),
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        begin = float(read_input(self, "timepoint"))
        elapsed = float(self.context.clock.now()) - begin
        self.logger.publish_info(f"StopwatchEnd: {elapsed:.3f} s elapsed since StopwatchBegin")
        if "elapsed_duration" in self.config.output_ports:
            write_output(self, "elapsed_duration", elapsed)
        return NodeStatus.SUCCESS
