"""LogMessage: show a message in the UI log (info, warning or error)."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

LEVELS = ("info", "warn", "error")


class LogMessage(SyncBehavior):
    """Publishes ``message`` at ``log_level`` (``info``, ``warn`` or ``error``) and succeeds.

    An ``error`` message is shown as a failure toast but does not fail the behavior; follow it with
    ``AlwaysFailure`` for that.
    """

    subcategory = "User Interface"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("message", str, "", "The text to show."),
            input_port("log_level", str, "info", "info, warn or error."),
        ]

    def tick(self) -> NodeStatus:
        message = str(self.get_input_or("message", ""))
        level = str(self.get_input("log_level")).strip().lower()
        if level in ("warning",):
            level = "warn"
        if level not in LEVELS:
            self.logger.publish_failure(f"LogMessage: log_level must be info, warn or error, got {level!r}")
            return NodeStatus.FAILURE
        if level == "info":
            self.logger.publish_info(message)
        elif level == "warn":
            self.logger.publish_warn(message)
        else:
            self.logger.publish_failure(message)
        return NodeStatus.SUCCESS
