"""Publish a planned joint trajectory for the 3D view (``kinema view`` draws the end effector's path)."""

from __future__ import annotations

from typing import Any

from kinema.ui_topics import PLANNED_TRAJECTORY_TOPIC, PLANNED_TRAJECTORY_TYPE


def publish_planned_trajectory(behavior: Any, message: Any) -> None:
    """Publish ``message`` (``trajectory_msgs/JointTrajectory``) on the planned-trajectory topic.

    Only for display: a context without a transport node (offline tests) publishes nothing.
    """
    node = behavior.context.node
    if node is None:
        return
    from kinema.transport import KEEP_ALL_QOS

    publisher = behavior.context.publisher(
        node, PLANNED_TRAJECTORY_TYPE, PLANNED_TRAJECTORY_TOPIC, qos=KEEP_ALL_QOS
    )
    publisher.publish(message)
