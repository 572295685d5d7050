"""GetPointCloud, GetImage and GetCameraInfo: the next message of a camera topic, onto the blackboard.

The MuJoCo driver renders a camera only while someone subscribes, so these behaviors subscribe, wait for
a publisher (``publisher_timeout_sec``) and then for one message (``message_timeout_sec``). A message
arrives after the subscription, so it shows the scene as it is now, not before the last motion — and
for images and clouds, whose renderer may still be sending a frame taken earlier (another subscriber
keeps the camera running; rendering takes its time on a loaded machine), the message must also be
stamped at or after the moment of subscription. (A stamp of zero or more than ``_OTHER_TIME_BASE`` s
before it is another time base, a camera clock not synchronised with the robot's: it is taken as it is.)
"""

from __future__ import annotations

import threading
import time
from typing import Any, ClassVar

from kinema.behaviors import AsyncBehavior, FormerSpelling, PortInfo, input_port
from kinema.behaviors.cell_ports import cell_input_port

from ..messages.ports import fails_on_bad_input, message_output, port_error, read_input
from .clouds import CAMERA_INFO, IMAGE, POINT_CLOUD

# How often the graph is looked at while waiting for a publisher, s.
_PUBLISHER_POLL = 0.05
# A stamp this far (s) before the subscription is not a stale frame but another clock.
_OTHER_TIME_BASE = 30.0


def taken_since(message: Any, start: float) -> bool:
    """Whether ``message`` (with a header) was stamped at or after ``start`` on the robot's clock."""
    stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
    return stamp == 0 or stamp >= start - 1e-6 or stamp < start - _OTHER_TIME_BASE


# MoveIt Pro's camera behaviors once had one timeout, for the message.
_OLD_TIMEOUT = (FormerSpelling(ports={"timeout_sec": "message_timeout_sec"}),)


class _GetCameraMessage(AsyncBehavior):
    message_type: ClassVar[str] = ""
    default_topic_key: ClassVar[str] = ""
    default_output: ClassVar[str] = ""
    # Only messages stamped since the subscription (a frame, not a camera's constant intrinsics).
    taken_now: ClassVar[bool] = True
    subcategory = "Perception - Camera"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            cell_input_port("topic_name", str, cls.default_topic_key, "The topic to take a message from."),
            input_port(
                "message_timeout_sec",
                float,
                5.0,
                "Seconds to wait for a message once a publisher is there (0 or less: forever).",
            ),
            input_port(
                "publisher_timeout_sec",
                float,
                5.0,
                "Seconds to wait for a publisher on the topic (0 or less: forever).",
            ),
            message_output("message_out", cls.message_type, cls.default_output, "The message received."),
        ]

    @fails_on_bad_input
    async def do_work(self) -> bool:
        import asyncio

        topic = str(read_input(self, "topic_name")).strip()
        if not topic.startswith("/"):
            raise port_error(
                self, "topic_name", f"= {topic!r}", "give an absolute topic, e.g. /<camera>/points"
            )
        message_timeout = float(read_input(self, "message_timeout_sec"))
        publisher_timeout = float(read_input(self, "publisher_timeout_sec"))
        node = self.context.require_node(self.registration_id)
        received: list[Any] = []
        arrived = threading.Event()

        start = self.context.clock.now()

        def on_message(message: Any) -> None:
            if arrived.is_set() or (self.taken_now and not taken_since(message, start)):
                return
            received.append(message)
            arrived.set()

        subscription = node.create_subscription(self.message_type, topic, on_message)
        try:
            found = await asyncio.to_thread(self._wait_for_publisher, node, topic, publisher_timeout, arrived)
            if not found:
                others = self._topics_of_type(node)
                hint = (
                    f"topics of this type: {', '.join(others)}" if others else "nothing publishes this type"
                )
                self.logger.publish_failure(
                    f"{self.registration_id}: no publisher on {topic} within {publisher_timeout:g} s "
                    f"(publisher_timeout_sec); {hint}"
                )
                return False
            got = await asyncio.to_thread(arrived.wait, None if message_timeout <= 0 else message_timeout)
        finally:
            subscription.close()
        if not got:
            self.logger.publish_failure(
                f"{self.registration_id}: no message on {topic} within {message_timeout:g} s "
                "(message_timeout_sec)"
            )
            return False
        self.set_output("message_out", received[0])
        return True

    def _wait_for_publisher(self, node: Any, topic: str, timeout: float, arrived: threading.Event) -> bool:
        graph = node.session.graph_cache()
        deadline = None if timeout <= 0 else time.monotonic() + timeout
        while not self.stop_requested():
            if arrived.is_set() or graph.snapshot().publishers(topic):
                return True
            if deadline is not None and time.monotonic() >= deadline:
                return False
            time.sleep(_PUBLISHER_POLL)
        return False

    def _topics_of_type(self, node: Any) -> list[str]:
        topics = node.session.graph_cache().snapshot().topics()
        return sorted(name for name, types in topics.items() if self.message_type in types)[:6]


class GetPointCloud(_GetCameraMessage):
    """Waits for the next ``sensor_msgs/PointCloud2`` on ``topic_name`` and writes it to ``message_out``.

    Simulated cameras publish ``/<camera>/points`` (organised clouds in the camera's optical frame; lab_sim:
    ``/scene_camera/points`` and ``/wrist_camera/points``). Fails when nothing publishes on the topic within
    ``publisher_timeout_sec`` (naming the topics that carry clouds) or no cloud comes within
    ``message_timeout_sec``. The cloud must be stamped at or after the moment the behavior subscribed: a
    frame rendered before the last motion, still on its way, is skipped.
    """

    message_type = POINT_CLOUD
    default_topic_key = "camera_points_topic"  # the config's camera: /<robot.default_camera>/points
    default_output = "{point_cloud}"
    subcategory = "Perception - 3D Point Cloud"
    former_spellings = _OLD_TIMEOUT


class GetImage(_GetCameraMessage):
    """Waits for the next ``sensor_msgs/Image`` on ``topic_name`` (``/wrist_camera/color``, say).

    The image must be stamped at or after the moment the behavior subscribed (see the module's notes).
    """

    message_type = IMAGE
    default_topic_key = "camera_color_topic"
    default_output = "{image}"
    subcategory = "Perception - 2D Image"
    former_spellings = _OLD_TIMEOUT


class GetCameraInfo(_GetCameraMessage):
    """Waits for the next ``sensor_msgs/CameraInfo`` on ``topic_name`` (a camera's intrinsics)."""

    message_type = CAMERA_INFO
    taken_now = False
    default_topic_key = "camera_info_topic"
    default_output = "{camera_info}"
    subcategory = "Perception - 2D Image"
    former_spellings = _OLD_TIMEOUT
