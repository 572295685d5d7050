"""The robot's current joint state for behaviors: the cell's :class:`~kinema.motion.JointStateMonitor`.

The monitor is ``BehaviorContext.joint_states``, made by the context on first use; this accessor names the
behavior when the context has no transport.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinema.behaviors import BehaviorContext
    from kinema.motion.joint_state_monitor import JointStateMonitor


def joint_state_monitor(context: BehaviorContext, behavior: str = "") -> JointStateMonitor:
    """The monitor shared by every behavior of ``context``.

    Raises:
        ObjectiveError: the context has no transport node (it names ``behavior``).
    """
    context.require_node(behavior)
    return context.joint_states
