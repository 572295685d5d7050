"""GetSyncedImageAndPointCloud: a colour image and a point cloud taken at the same moment, with the
camera's intrinsics."""

from __future__ import annotations

import threading
from typing import Any

from kinema.behaviors import AsyncBehavior, PortInfo, input_port
from kinema.behaviors.cell_ports import cell_input_port

from ..messages.conversions import seconds
from ..messages.ports import fails_on_bad_input, message_output, port_error, read_input
from .camera_topics import taken_since
from .clouds import CAMERA_INFO, IMAGE, POINT_CLOUD

# Stamps this close (s) are one moment: a simulated camera stamps the image and the cloud of one render
# alike; a real RGB-D camera's streams are a few milliseconds apart.
SYNC_SLOP = 0.01
# The last messages of each stream looked at for a partner.
_KEPT = 10


class GetSyncedImageAndPointCloud(AsyncBehavior):
    """Waits for an image on ``rgb_image_topic_name`` and a point cloud on ``point_cloud_topic_name`` taken
    at the same moment (stamps within 10 ms), both taken after the behavior started, and the camera's
    ``sensor_msgs/CameraInfo``; writes the three.

    Segmenting an image and reading the 3D points of the masks needs a cloud of the same view: taken one
    after the other with GetImage and GetPointCloud they may show different moments. Fails when no such
    pair (or no camera info) arrives within ``message_timeout_sec``, naming the stream that was missing.
    """

    subcategory = "Perception - Camera"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            cell_input_port("point_cloud_topic_name", str, "camera_points_topic", "The point cloud topic."),
            cell_input_port("rgb_image_topic_name", str, "camera_color_topic", "The colour image topic."),
            cell_input_port("rgb_camera_info_topic_name", str, "camera_info_topic", "The camera info topic."),
            input_port(
                "message_timeout_sec",
                float,
                5.0,
                "Seconds to wait for a matching pair (MoveIt Pro's port list here is not public; Kinema's "
                "camera behaviors' timeout).",
            ),
            message_output("point_cloud", POINT_CLOUD, "{point_cloud}", "The cloud."),
            message_output("rgb_image", IMAGE, "{rgb_image}", "The image taken with it."),
            message_output("rgb_camera_info", CAMERA_INFO, "{rgb_camera_info}", "The camera's intrinsics."),
        ]

    @fails_on_bad_input
    async def do_work(self) -> bool:
        import asyncio

        topics = {}
        for port in ("point_cloud_topic_name", "rgb_image_topic_name", "rgb_camera_info_topic_name"):
            topic = str(read_input(self, port)).strip()
            if not topic.startswith("/"):
                raise port_error(
                    self, port, f"= {topic!r}", "give an absolute topic, e.g. /<camera>/points"
                )
            topics[port] = topic
        timeout = float(read_input(self, "message_timeout_sec"))
        node = self.context.require_node(self.registration_id)
        start = self.context.clock.now()
        lock = threading.Lock()
        ready = threading.Event()
        clouds: list[Any] = []
        images: list[Any] = []
        infos: list[Any] = []
        found: list[tuple[Any, Any]] = []

        def match() -> None:
            for cloud in reversed(clouds):
                for image in reversed(images):
                    if abs(seconds(cloud.header.stamp) - seconds(image.header.stamp)) <= SYNC_SLOP:
                        found.append((cloud, image))
                        return

        def keep(into: list[Any], fresh: bool) -> Any:
            def on_message(message: Any) -> None:
                if ready.is_set() or (fresh and not taken_since(message, start)):
                    return
                with lock:
                    into.append(message)
                    del into[:-_KEPT]
                    if not found:
                        match()
                    if found and infos:
                        ready.set()

            return on_message

        subscriptions = [
            node.create_subscription(POINT_CLOUD, topics["point_cloud_topic_name"], keep(clouds, True)),
            node.create_subscription(IMAGE, topics["rgb_image_topic_name"], keep(images, True)),
            node.create_subscription(CAMERA_INFO, topics["rgb_camera_info_topic_name"], keep(infos, False)),
        ]
        try:
            got = await asyncio.to_thread(ready.wait, None if timeout <= 0 else timeout)
        finally:
            for subscription in subscriptions:
                subscription.close()
        if not got:
            with lock:
                missing = [
                    f"no cloud on {topics['point_cloud_topic_name']}" if not clouds else "",
                    f"no image on {topics['rgb_image_topic_name']}" if not images else "",
                    f"no camera info on {topics['rgb_camera_info_topic_name']}" if not infos else "",
                    "no image and cloud within 10 ms of each other"
                    if clouds and images and not found
                    else "",
                ]
            self.logger.publish_failure(
                f"GetSyncedImageAndPointCloud: within {timeout:g} s (message_timeout_sec): "
                + "; ".join(m for m in missing if m)
            )
            return False
        cloud, image = found[0]
        self.set_output("point_cloud", cloud)
        self.set_output("rgb_image", image)
        self.set_output("rgb_camera_info", infos[-1])
        return True
