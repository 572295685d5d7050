"""ComputeTrayPlacePositionsUsingAprilTags: the slots of a tray, laid out from the AprilTag beside them.

MoveIt Pro ships this behavior with lab_sim (its ``LabSimBehaviorsLoader``) and documents only its
ports; what it does here is what ``pick_all_bottles_with_apriltags.xml`` implies, chosen as follows and
repeated in each port's description:

* The tray's tag lies flat beside the slots. The tray's centre is ``tag_to_tray_center`` metres from the
  tag's centre along the tag's +y axis (up its columns as printed), in the tag's plane.
* ``num_rows`` rows ``row_spacing`` apart run along the tag's x axis; each row holds ``columns_per_row``
  slots ``column_spacing`` apart along the tag's y axis. The grid is centred on the tray's centre; slots
  are listed row by row (tag -x to +x), within a row from the tag outward.
* Each place pose sits at the tag's height (the tray's floor) with its z axis into the tray (the tag's
  frame turned half a turn about its x axis), so a gripper frame sent there approaches from above; the
  poses are expressed in ``world`` (the robot then moves, so the camera's frame would not stay valid).
* ``bottle_diameter`` is checked against the spacings (neighbouring bottles must not overlap) and drawn:
  when ``visualization_topic`` is set, ``input_image`` is published there with the tag's centre and a
  circle of the bottle's size at each slot (projected with ``camera_info``), for the TUI's image view.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import KinemaError

from ..files.image_file import image_message, image_pixels
from ..messages.conversions import POSE_STAMPED_TYPE, pose_stamped_message
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    message_vector_output,
    port_error,
    read_input,
    read_message,
    read_text,
)
from .apriltags import DETECTIONS
from .clouds import CAMERA_INFO, IMAGE

# The place frame in the tag's frame: a half turn about x, z into the tray.
_FLIP = (1.0, -1.0, -1.0)  # the diagonal (a tuple: loading the plugin must not import numpy)


def slot_offsets(rows: int, columns: int, row_spacing: float, column_spacing: float) -> np.ndarray:
    """``(rows * columns, 2)`` slot centres (x, y) about the tray's centre, row by row."""
    import numpy as np

    xs = (np.arange(rows) - (rows - 1) / 2) * row_spacing
    ys = (np.arange(columns) - (columns - 1) / 2) * column_spacing
    return np.array([(x, y) for x in xs for y in ys], dtype=float)


def place_poses_in_tag_frame(
    rows: int, columns: int, row_spacing: float, column_spacing: float, tag_to_center: float
) -> list[np.ndarray]:
    """The 4x4 place poses in the tag's frame (see the module's docstring for the layout)."""
    import numpy as np

    poses = []
    for x, y in slot_offsets(rows, columns, row_spacing, column_spacing):
        pose = np.eye(4)
        pose[:3, :3] = np.diag(_FLIP)
        pose[:3, 3] = [x, tag_to_center + y, 0.0]
        poses.append(pose)
    return poses


class ComputeTrayPlacePositionsUsingAprilTags(SyncBehavior):
    """Writes the place poses of a tray's slots, laid out from the tray's AprilTag.

    Finds the detection of ``tray_apriltag_id``, steps ``tag_to_tray_center`` along the tag's +y axis to
    the tray's centre and lays ``num_rows`` x ``columns_per_row`` slots around it (rows along the tag's
    x, columns along its y), each a PoseStamped in ``world`` at the tray floor with z pointing into the
    tray. Fails naming the port when the tag is missing or the layout is impossible.
    """

    subcategory = "Perception - 2D Image"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "detections", DETECTIONS, "{detections}", "Tag detections, e.g. from DetectAprilTags."
            ),
            message_input(
                "camera_info",
                CAMERA_INFO,
                "{camera_info}",
                "The intrinsics of the camera that took input_image; used to draw the slots.",
            ),
            message_input(
                "input_image",
                IMAGE,
                "{image}",
                "The image the tags were found in; drawn on and published to visualization_topic.",
            ),
            input_port("tray_apriltag_id", int, 1, "The number of the AprilTag beside the tray's slots."),
            input_port("num_rows", int, 3, "Rows of slots (>= 1), laid along the tag's x axis."),
            input_port("columns_per_row", int, 2, "Slots in each row (>= 1), laid along the tag's y axis."),
            input_port("row_spacing", float, 0.10, "Distance between neighbouring rows (m)."),
            input_port("column_spacing", float, 0.09, "Distance between neighbouring slots of a row (m)."),
            input_port(
                "tag_to_tray_center",
                float,
                0.125,
                "Distance from the tag's centre to the tray's centre along the tag's +y axis (m).",
            ),
            input_port(
                "bottle_diameter",
                float,
                0.04,
                "Diameter of what is placed (m): the spacings must be at least this; drawn at each slot.",
            ),
            message_vector_output(
                "place_positions",
                POSE_STAMPED_TYPE,
                "{place_positions}",
                "One pose per slot, in world, at the tray floor with z pointing into the tray; row by "
                "row (tag -x to +x), within a row from the tag outward.",
            ),
            input_port(
                "visualization_topic",
                str,
                "/apriltag_detections",
                "Image topic the annotated input_image is published on (tag centre, slot circles); "
                "'': publish nothing.",
            ),
        ]

    def _layout(self) -> tuple[int, int, float, float, float, float]:
        import numpy as np

        rows = int(read_input(self, "num_rows"))
        columns = int(read_input(self, "columns_per_row"))
        row_spacing = float(read_input(self, "row_spacing"))
        column_spacing = float(read_input(self, "column_spacing"))
        tag_to_center = float(read_input(self, "tag_to_tray_center"))
        diameter = float(read_input(self, "bottle_diameter"))
        for port, value in (("num_rows", rows), ("columns_per_row", columns)):
            if value < 1:
                raise port_error(self, port, f"= {value}", "expected a whole number of slots, 1 or more")
        if not diameter > 0:
            raise port_error(self, "bottle_diameter", f"= {diameter}", "expected the diameter in metres, > 0")
        for port, value, count in (
            ("row_spacing", row_spacing, rows),
            ("column_spacing", column_spacing, columns),
        ):
            if count > 1 and not value >= diameter:
                raise port_error(
                    self,
                    port,
                    f"= {value}",
                    f"neighbouring slots would overlap: expected at least bottle_diameter ({diameter}) m",
                )
        if not np.isfinite(tag_to_center):
            raise port_error(
                self, "tag_to_tray_center", f"= {tag_to_center}", "expected a distance in metres"
            )
        return rows, columns, row_spacing, column_spacing, tag_to_center, diameter

    def _tag_pose(self, detections: Any, tag_id: int) -> tuple[str, Any, np.ndarray]:
        from kinema.transforms import pose_from_message

        for detection in detections.detections:
            if str(detection.id).strip() == str(tag_id) and detection.results:
                best = max(detection.results, key=lambda r: float(r.hypothesis.score))
                frame = str(detection.header.frame_id) or str(detections.header.frame_id)
                return frame, detection.header.stamp, pose_from_message(best.pose.pose)
        seen = ", ".join(str(d.id) for d in detections.detections) or "none"
        raise port_error(
            self,
            "tray_apriltag_id",
            f"= {tag_id}: no detection with that id",
            f"ids detected: {seen} (the tray's tag must be in the image DetectAprilTags looked at)",
        )

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        rows, columns, row_spacing, column_spacing, tag_to_center, diameter = self._layout()
        detections = read_message(self, "detections")
        frame, stamp, frame_T_tag = self._tag_pose(detections, int(read_input(self, "tray_apriltag_id")))
        in_tag = place_poses_in_tag_frame(rows, columns, row_spacing, column_spacing, tag_to_center)
        in_frame = [frame_T_tag @ pose for pose in in_tag]
        if frame in ("", "world"):
            world = in_frame
        else:
            from ..poses.frame_tree import current_frame_tree

            try:
                world_T_frame = current_frame_tree(self).world_T(frame)
            except KinemaError as error:
                self.logger.publish_failure(
                    f"ComputeTrayPlacePositionsUsingAprilTags: cannot express the detections' frame "
                    f"{frame!r} in world: {error}"
                )
                return NodeStatus.FAILURE
            world = [world_T_frame @ pose for pose in in_frame]
        messages = []
        for pose in world:
            message = pose_stamped_message("world", pose)
            message.header.stamp = stamp
            messages.append(message)
        topic = read_text(self, "visualization_topic").strip()
        if topic:
            self._publish_drawing(topic, frame_T_tag, in_frame, diameter)
        self.set_output("place_positions", messages)
        centre = (world[0][:3, 3] + world[-1][:3, 3]) / 2
        self.logger.publish_info(
            f"ComputeTrayPlacePositionsUsingAprilTags: {len(messages)} place positions around "
            f"({centre[0]:.3f}, {centre[1]:.3f}, {centre[2]:.3f}) in world"
        )
        return NodeStatus.SUCCESS

    def _publish_drawing(
        self, topic: str, camera_T_tag: np.ndarray, camera_T_slots: list[np.ndarray], diameter: float
    ) -> None:
        import numpy as np
        from PIL import Image, ImageDraw

        from kinema.perception.ros_messages import intrinsics_of

        image = read_message(self, "input_image")
        info = read_message(self, "camera_info")
        if int(info.width) <= 0 or float(np.asarray(info.k, dtype=float)[0]) <= 0:
            raise port_error(
                self,
                "camera_info",
                "has no intrinsics (width 0 or fx 0)",
                "expected GetCameraInfo's output, or set visualization_topic to '' to draw nothing",
            )
        intrinsics = intrinsics_of(info)
        pixels, mode = image_pixels(self, "input_image", image)
        if mode == "L":
            pixels = np.repeat(pixels[:, :, None], 3, axis=2)
        canvas = Image.fromarray(np.array(pixels[:, :, :3], dtype=np.uint8))
        draw = ImageDraw.Draw(canvas)

        def project(point: np.ndarray) -> tuple[float, float, float] | None:
            x, y, z = (float(v) for v in point)
            if z <= 1e-6:
                return None
            return intrinsics.fx * x / z + intrinsics.cx, intrinsics.fy * y / z + intrinsics.cy, z

        tag = project(camera_T_tag[:3, 3])
        if tag is not None:
            u, v, _ = tag
            draw.line([(u - 8, v), (u + 8, v)], fill=(230, 25, 75), width=2)
            draw.line([(u, v - 8), (u, v + 8)], fill=(230, 25, 75), width=2)
        for slot in camera_T_slots:
            seen = project(slot[:3, 3])
            if seen is None:
                continue
            u, v, z = seen
            r = intrinsics.fx * diameter / 2 / z
            draw.ellipse([(u - r, v - r), (u + r, v + r)], outline=(60, 180, 75), width=2)
        node = self.context.require_node(self.registration_id)
        frame = str(image.header.frame_id)
        self.context.publisher(node, IMAGE, topic).publish(image_message(np.asarray(canvas), "rgb8", frame))
