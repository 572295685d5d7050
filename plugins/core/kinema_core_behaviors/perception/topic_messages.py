"""GetImage, GetCameraInfo and GetPointCloud: the next message a camera publishes, as MoveIt Pro gets it.

Each waits up to ``publisher_timeout_sec`` for someone to publish on ``topic_name``, then up to
``message_timeout_sec`` for the next message, and writes it to ``message_out``. The simulated cameras
render only while a topic has subscribers, so the message is a fresh frame of the current scene.
"""

from __future__ import annotations

import threading
import time
from typing import Any, ClassVar

from kinema.behaviors import AsyncBehavior, PortInfo, input_port

from ..messages.ports import fails_on_bad_input, message_output, port_error, read_input

# How often a waiting behavior looks whether it was halted, s.
_HALT_POLL = 0.05


class _GetCameraMessage(AsyncBehavior):
    """Waits for a publisher, then for one message of :attr:`ros_type` on ``topic_name``."""

    ros_type: ClassVar[str] = ""
    default_topic: ClassVar[str] = ""
    default_output: ClassVar[str] = "{message_out}"
    what: ClassVar[str] = "message"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("topic_name", str, cls.default_topic, f"The topic to take the {cls.what} from."),
            input_port(
                "publisher_timeout_sec",
                float,
                5.0,
                "Seconds to wait for a publisher on the topic (0 or less: forever).",
            ),
            input_port(
                "message_timeout_sec",
                float,
                5.0,
                "Seconds to wait for a message once the topic has a publisher (0 or less: forever).",
            ),
            message_output("message_out", cls.ros_type, cls.default_output, f"The {cls.what} received."),
        ]

    def _wait(self, ready: Any, timeout: float) -> bool:
        """Poll ``ready()`` until true, ``timeout`` (≤ 0: never) or a halt; True when it became true."""
        deadline = None if timeout <= 0 else time.monotonic() + timeout
        while not ready():
            if self.stop_requested() or (deadline is not None and time.monotonic() >= deadline):
                return False
            time.sleep(_HALT_POLL)
        return True

    @fails_on_bad_input
    def do_work(self) -> bool:
        topic = str(read_input(self, "topic_name")).strip()
        if not topic:
            raise port_error(self, "topic_name", "is empty", f"e.g. {self.default_topic}")
        publisher_timeout = float(read_input(self, "publisher_timeout_sec"))
        message_timeout = float(read_input(self, "message_timeout_sec"))
        node = self.context.require_node(self.registration_id)
        name = node.resolve(topic)
        graph = node.session.graph_cache()
        if not self._wait(lambda: bool(graph.snapshot().publishers(name)), publisher_timeout):
            if not self.stop_requested():
                topics = sorted(t for t, types in graph.snapshot().topics().items() if self.ros_type in types)
                self.logger.publish_failure(
                    f"{self.registration_id}: nobody published on {name} within {publisher_timeout:g} s; "
                    f"{self.ros_type} topics now: {', '.join(topics) or 'none'}"
                )
            return False
        received: list[Any] = []
        arrived = threading.Event()

        def on_message(message: Any) -> None:
            if not arrived.is_set():
                received.append(message)
                arrived.set()

        subscription = node.create_subscription(self.ros_type, name, on_message)
        try:
            got = self._wait(arrived.is_set, message_timeout)
        finally:
            subscription.close()
        if not got:
            if not self.stop_requested():
                self.logger.publish_failure(
                    f"{self.registration_id}: no {self.what} on {name} within {message_timeout:g} s "
                    "(it has a publisher)"
                )
            return False
        self.set_output("message_out", received[0])
        return True


class GetImage(_GetCameraMessage):
    """Writes the next ``sensor_msgs/Image`` on ``topic_name`` (e.g. ``/wrist_camera/color``)."""

    subcategory = "Perception - 2D Image"
    ros_type = "sensor_msgs/msg/Image"
    default_topic = "/wrist_camera/color"
    default_output = "{image}"
    what = "image"


class GetCameraInfo(_GetCameraMessage):
    """Writes the next ``sensor_msgs/CameraInfo`` on ``topic_name`` (a camera's intrinsics)."""

    subcategory = "Perception - 2D Image"
    ros_type = "sensor_msgs/msg/CameraInfo"
    default_topic = "/wrist_camera/camera_info"
    default_output = "{camera_info}"
    what = "camera info"


class GetPointCloud(_GetCameraMessage):
    """Writes the next ``sensor_msgs/PointCloud2`` on ``topic_name`` (e.g. ``/wrist_camera/points``)."""

    subcategory = "Perception - 3D Point Cloud"
    ros_type = "sensor_msgs/msg/PointCloud2"
    default_topic = "/wrist_camera/points"
    default_output = "{point_cloud}"
    what = "point cloud"
