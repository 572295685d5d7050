"""The objective server's states, as ``moveit_studio_agent_msgs/msg/ObjectiveServerStatus`` spells them."""

from __future__ import annotations

from enum import StrEnum


class ObjectiveStatus(StrEnum):
    """What the objective server is doing; the heartbeat carries the string value."""

    UNKNOWN = "Unknown"
    IDLE = "Idle"
    LOADING = "Loading"
    RUNNING = "Running"
    SUCCESS = "Success"
    FAILURE = "Failure"
    CANCELLED = "Cancelled"

    @property
    def is_active(self) -> bool:
        """True while an objective is being loaded or ticked."""
        return self in (ObjectiveStatus.LOADING, ObjectiveStatus.RUNNING)
