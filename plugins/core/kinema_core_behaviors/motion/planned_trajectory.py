"""Publish a planned joint trajectory for the 3D view (``kinema view`` draws the end effector's path)."""

from __future__ import annotations

from typing import Any

from kinema.ui_topics import PLANNED_TRAJECTORY_TOPIC, PLANNED_TRAJECTORY_TYPE


def publish_planned_trajectory(behavior: Any, message: Any) -> None:
    """Publish ``message`` (``trajectory_msgs/JointTrajectory``) on the planned-trajectory topic.

    Only for display: a context without a transport node (offline tests) publishes nothing, and the
    message last published is not published again (PlanToJointGoal publishes the plan, and
    ExecuteTrajectory the same message object as it starts it: the topic already shows it).
    """
    node = behavior.context.node
    if node is None:
        return
    last = behavior.context.shared("planned_trajectory_published", lambda: [None])
    if last[0] is message:
        return
    last[0] = message
    from kinema.transport import KEEP_ALL_QOS

    publisher = behavior.context.publisher(
        node, PLANNED_TRAJECTORY_TYPE, PLANNED_TRAJECTORY_TOPIC, qos=KEEP_ALL_QOS
    )
    publisher.publish(message)
