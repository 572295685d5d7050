"""Node statuses, as BT.CPP numbers them (IDLE=0 ... SKIPPED=4)."""

from __future__ import annotations

from enum import IntEnum


class NodeStatus(IntEnum):
    """The result of ticking a node.

    IDLE means "not started, or reset"; a node never returns it. SKIPPED is returned to the parent but
    never stored as a node's own status (the node stays IDLE).
    """

    IDLE = 0
    RUNNING = 1
    SUCCESS = 2
    FAILURE = 3
    SKIPPED = 4

    def __str__(self) -> str:
        return self.name

    @property
    def is_active(self) -> bool:
        """True unless IDLE or SKIPPED."""
        return self is not NodeStatus.IDLE and self is not NodeStatus.SKIPPED

    @property
    def is_completed(self) -> bool:
        """True for SUCCESS and FAILURE."""
        return self is NodeStatus.SUCCESS or self is NodeStatus.FAILURE


# Module-level aliases: the tick path compares statuses by identity against these, which avoids the
# class-attribute lookup through the enum metaclass on every comparison.
IDLE = NodeStatus.IDLE
RUNNING = NodeStatus.RUNNING
SUCCESS = NodeStatus.SUCCESS
FAILURE = NodeStatus.FAILURE
SKIPPED = NodeStatus.SKIPPED

STATUS_BY_NAME: dict[str, NodeStatus] = {s.name: s for s in NodeStatus}
