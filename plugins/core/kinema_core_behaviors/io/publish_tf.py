"""PublishTF: broadcast a pose as a named frame while the behavior runs (MoveIt Pro's TF broadcaster)."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import FormerSpelling, NodeStatus, PortInfo, StatefulBehavior, input_port
from kinema.ui_topics import TF_TOPIC, TF_TYPE

from ..messages.conversions import POSE_STAMPED_TYPE, pose_matrix
from ..messages.ports import fails_on_bad_input, message_input, port_error, read_input, read_message


class PublishTF(StatefulBehavior):
    """Makes ``pose`` a frame named ``child_frame_id`` (its parent the pose's frame) and keeps it there while
    it runs: it never finishes by itself; put it in a Parallel beside the work that uses the frame, or
    under a Timeout.

    While it runs, Kinema's behaviors resolve ``child_frame_id`` like any frame of the cell (a frame
    published in a robot link's frame moves with the robot), and it is sent ``publish_rate`` times a
    second on ``/tf`` (``tf2_msgs/TFMessage``) for ``kinema view`` and any ROS tool. When it is halted the
    frame stays known for 10 s, as a TF listener keeps the last transform it heard. Fails when the pose is
    not a PoseStamped, the frame name is empty or the pose's own frame, or the rate is not positive.
    """

    subcategory = "Math - Poses"
    # MoveIt Pro's older broadcaster of a pose as a (static) frame, with the same ports but the rate.
    former_spellings = (FormerSpelling("PublishStaticFrame"),)

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("pose", POSE_STAMPED_TYPE, "{pose}", "The frame's pose, in its parent frame."),
            input_port("child_frame_id", str, "", "Name of the frame to publish."),
            input_port("publish_rate", float, 5.0, "How often it is sent on /tf (Hz)."),
        ]

    @fails_on_bad_input
    def on_start(self) -> NodeStatus:
        parent, matrix = pose_matrix(read_message(self, "pose"), "pose")
        child = (
            str(read_input(self, "child_frame_id")).strip()
            if "child_frame_id" in self.config.input_ports
            else ""
        )
        if not child:
            raise port_error(self, "child_frame_id", "is empty", "name the frame, e.g. 'object_frame'")
        if child == (parent or "world"):
            raise port_error(
                self, "child_frame_id", f"= {child!r} is the pose's own frame", "name a new frame"
            )
        rate = float(read_input(self, "publish_rate"))
        if not rate > 0:
            raise port_error(self, "publish_rate", f"= {rate:g}", "give a rate > 0 Hz, e.g. 5")
        self._frame: tuple[str, str, Any] = (child, parent or "world", matrix)
        self._period = 1.0 / rate
        self.context.frames.publish(child, parent or "world", matrix)
        self._last_sent = float("-inf")
        self._send()
        return NodeStatus.RUNNING

    def on_running(self) -> NodeStatus:
        if self.context.clock.now() - self._last_sent >= self._period:
            self._send()
        return NodeStatus.RUNNING

    def on_halted(self) -> None:
        self.context.frames.release(self._frame[0])

    def _send(self) -> None:
        node = self.context.node
        self._last_sent = self.context.clock.now()
        if node is None:
            return  # offline (a unit test): the frame is known to the cell, nothing goes on the network
        from kinema.transforms import pose_parts
        from kinema.transport import from_dict

        child, parent, matrix = self._frame
        (x, y, z), (qx, qy, qz, qw) = pose_parts(matrix)
        sec = int(self._last_sent)
        message = {
            "transforms": [
                {
                    "header": {
                        "frame_id": parent,
                        "stamp": {"sec": sec, "nanosec": int((self._last_sent - sec) * 1e9)},
                    },
                    "child_frame_id": child,
                    "transform": {
                        "translation": {"x": float(x), "y": float(y), "z": float(z)},
                        "rotation": {"x": float(qx), "y": float(qy), "z": float(qz), "w": float(qw)},
                    },
                }
            ]
        }
        self.context.publisher(node, TF_TYPE, TF_TOPIC).publish(from_dict(TF_TYPE, message))
