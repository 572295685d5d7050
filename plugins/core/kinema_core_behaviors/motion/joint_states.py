"""The robot's current joint state, as the driver publishes it on ``/joint_states``.

One :class:`JointStateMonitor` is shared by every behavior of a context (the subscription lives as long
as the context's transport node), so planning behaviors can read the start state without waiting for
the next message.
"""

from __future__ import annotations

import threading
import time
import weakref
from collections.abc import Sequence
from typing import Any

import numpy as np

from kinema.errors import ObjectiveError

JOINT_STATES_TOPIC = "/joint_states"
JOINT_STATES_TYPE = "sensor_msgs/msg/JointState"

_MONITORS: weakref.WeakKeyDictionary[Any, JointStateMonitor] = weakref.WeakKeyDictionary()
_MONITORS_LOCK = threading.Lock()


class JointStateMonitor:
    """Keeps the latest ``/joint_states`` message.

    Args:
        node: the transport node to subscribe on.
        topic: the joint state topic.
    """

    def __init__(self, node: Any, topic: str = JOINT_STATES_TOPIC) -> None:
        self.topic = topic
        self._latest: Any = None
        self._received_at = 0.0
        self._changed = threading.Condition()
        self._subscription = node.create_subscription(JOINT_STATES_TYPE, topic, self._on_message)

    def _on_message(self, message: Any) -> None:
        with self._changed:
            self._latest = message
            self._received_at = time.monotonic()
            self._changed.notify_all()

    def latest(self, timeout: float = 2.0) -> Any:
        """The latest message; waits up to ``timeout`` s for the first one.

        Raises:
            ObjectiveError: nothing was received within ``timeout`` (no driver running).
        """
        with self._changed:
            if self._latest is None and not self._changed.wait_for(lambda: self._latest is not None, timeout):
                raise ObjectiveError(
                    f"no joint state received on {self.topic} within {timeout:g} s; is the robot driver "
                    "running (`kinema run`)?"
                )
            return self._latest

    def fresh(self, timeout: float = 2.0) -> Any:
        """The next message received from now on (a state at least as new as this call)."""
        with self._changed:
            since = self._received_at
            if not self._changed.wait_for(lambda: self._received_at > since, timeout):
                raise ObjectiveError(
                    f"no joint state received on {self.topic} within {timeout:g} s; is the robot driver "
                    "running (`kinema run`)?"
                )
            return self._latest

    def positions(self, joint_names: Sequence[str], timeout: float = 2.0) -> np.ndarray:
        """Latest positions of ``joint_names``, in that order.

        Raises:
            ObjectiveError: no message yet, or a joint is missing from it.
        """
        message = self.latest(timeout)
        index = {str(name): i for i, name in enumerate(message.name)}
        missing = [name for name in joint_names if name not in index]
        if missing:
            raise ObjectiveError(
                f"{self.topic} does not report joint(s) {', '.join(missing)} "
                f"(it reports {', '.join(index) or 'none'})"
            )
        return np.array([float(message.position[index[name]]) for name in joint_names])

    def close(self) -> None:
        """Stop listening."""
        self._subscription.close()


def joint_state_monitor(context: Any, behavior: str = "") -> JointStateMonitor:
    """The monitor shared by every behavior of ``context`` (created on first use)."""
    node = context.require_node(behavior)
    with _MONITORS_LOCK:
        monitor = _MONITORS.get(context)
        if monitor is None:
            monitor = JointStateMonitor(node)
            _MONITORS[context] = monitor
        return monitor
