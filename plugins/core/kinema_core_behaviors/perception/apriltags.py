"""DetectAprilTags and GetDetectionPose: find AprilTags in a camera image and pick one's pose.

DetectAprilTags runs AprilTag 3 (:mod:`kinema.perception.apriltags`) on an ``sensor_msgs/Image`` with
the camera's ``sensor_msgs/CameraInfo`` and writes a ``vision_msgs/Detection3DArray`` in the image's
frame: one detection per tag, ``id`` = the tag's number, one result whose ``class_id`` is the family
(``tag36h11``), whose score is the decoding's decision margin scaled to 0..1 and whose pose is the tag's
centre (z out of the tag's face). GetDetectionPose picks one detection by id and/or label and writes
its pose as a ``geometry_msgs/PoseStamped`` in the same frame (``TransformPoseFrame`` takes it to the
world).
"""

from __future__ import annotations

from typing import Any

from kinema.behaviors import AsyncBehavior, FormerSpelling, NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import PerceptionError

from ..files.image_file import image_pixels
from ..messages.conversions import pose_stamped_message
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    message_output,
    port_error,
    read_input,
    read_message,
    read_text,
)
from .clouds import CAMERA_INFO, IMAGE

DETECTIONS = "vision_msgs/msg/Detection3DArray"
POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
# A decision margin this high (or more) is scored 1.0; the library's margins run to a few hundred.
_FULL_MARGIN = 100.0


def detections_message(detections: list[Any], header: Any, tag_size: float) -> Any:
    """The ``vision_msgs/Detection3DArray`` of :class:`~kinema.perception.apriltags.TagDetection` s."""
    from kinema.transforms import pose_dict
    from kinema.transport import from_dict, to_dict

    header_dict = to_dict(header)
    return from_dict(
        DETECTIONS,
        {
            "header": header_dict,
            "detections": [
                {
                    "header": header_dict,
                    "id": str(tag.tag_id),
                    "results": [
                        {
                            "hypothesis": {
                                "class_id": tag.family,
                                "score": min(1.0, tag.decision_margin / _FULL_MARGIN),
                            },
                            "pose": {"pose": pose_dict(tag.camera_T_tag)},
                        }
                    ],
                    "bbox": {
                        "center": pose_dict(tag.camera_T_tag),
                        "size": {"x": tag_size, "y": tag_size, "z": 0.0},
                    },
                }
                for tag in detections
            ],
        },
    )


class DetectAprilTags(AsyncBehavior):
    """Finds the AprilTags of one family in ``image`` and writes their poses to ``detections``."""

    subcategory = "Perception - 2D Image"
    former_spellings = (
        FormerSpelling(
            # the name its parameter files (LoadObjectiveParameters) gave the tag size
            ports={"apriltag_size": "tag_size"},
            dropped={
                "parameters": "the detector's settings are its own ports today (apriltag_family_name, "
                "tag_size, max_hamming, n_threads, quad_decimate, quad_sigma, refine_edges)"
            },
        ),
    )

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("image", IMAGE, "{image}", "The camera image (rgb8, bgr8, mono8, ...)."),
            message_input("camera_info", CAMERA_INFO, "{camera_info}", "The camera's intrinsics."),
            message_output(
                "detections",
                DETECTIONS,
                "{detections}",
                "One detection per tag found (id = tag number), in the image's frame.",
            ),
            input_port(
                "apriltag_family_name",
                str,
                "36h11",
                "Tag family: 36h11, 25h9, 16h5, Circle21h7, Circle49h12, Standard41h12, Standard52h13, "
                "Custom48h12.",
            ),
            input_port("tag_size", float, 0.0288, "Side of the tag's black square (m)."),
            input_port("max_hamming", int, 0, "Most bit errors a detection may have had corrected."),
            input_port("n_threads", int, 1, "Threads the detector uses."),
            input_port(
                "quad_decimate",
                float,
                2.0,
                "Find quads in an image this many times smaller (faster; the edges are refined at "
                "full size).",
            ),
            input_port("quad_sigma", float, 0.0, "Gaussian blur (pixels) before finding quads; 0: none."),
            input_port("refine_edges", bool, True, "Snap quad edges to the strongest nearby gradients."),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        import numpy as np

        from kinema.perception.apriltags import DetectorSettings, detect_tags, family_name
        from kinema.perception.ros_messages import intrinsics_of

        image = read_message(self, "image")
        info = read_message(self, "camera_info")
        try:
            family = family_name(str(read_input(self, "apriltag_family_name")))
        except PerceptionError as error:
            raise port_error(
                self, "apriltag_family_name", str(error).split("; ")[0], str(error).split("; ")[-1]
            ) from None
        tag_size = float(read_input(self, "tag_size"))
        if not tag_size > 0:
            raise port_error(
                self, "tag_size", f"= {tag_size}", "expected the black square's side in metres, > 0"
            )
        max_hamming = int(read_input(self, "max_hamming"))
        if not 0 <= max_hamming <= 3:
            raise port_error(self, "max_hamming", f"= {max_hamming}", "valid: 0..3")
        decimate = float(read_input(self, "quad_decimate"))
        if not decimate >= 1.0:
            raise port_error(self, "quad_decimate", f"= {decimate}", "expected 1.0 or more")
        settings = DetectorSettings(
            family,
            max_hamming,
            max(1, int(read_input(self, "n_threads"))),
            decimate,
            max(0.0, float(read_input(self, "quad_sigma"))),
            bool(read_input(self, "refine_edges")),
        )
        if int(info.width) <= 0 or float(np.asarray(info.k, dtype=float)[0]) <= 0:
            raise port_error(
                self, "camera_info", "has no intrinsics (width 0 or fx 0)", "expected GetCameraInfo's output"
            )
        pixels, _mode = image_pixels(self, "image", image)
        try:
            found = detect_tags(pixels, intrinsics_of(info), tag_size, settings)
        except PerceptionError as error:
            raise port_error(
                self, "image", str(error), "the image and camera_info must come from one camera"
            ) from None
        self.set_output("detections", detections_message(found, image.header, tag_size))
        if found:
            tags = ", ".join(f"{tag.family}:{tag.tag_id}" for tag in found)
            self.logger.publish_info(f"DetectAprilTags: {len(found)} tag(s): {tags}")
        else:
            self.logger.publish_info(f"DetectAprilTags: no {family} tag in the image")
        return True


class GetDetectionPose(SyncBehavior):
    """Writes the pose of the detection with ``target_id`` (-1: any) and ``target_label`` ('': any).

    Fails when no detection matches, naming the ids and labels there were. Among several matches the
    one with the best score is taken.
    """

    subcategory = "Perception - 2D Image"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("detections", DETECTIONS, "{detections}", "Detections, e.g. from DetectAprilTags."),
            input_port("target_id", int, -1, "The detection's id (an AprilTag's number); -1: any."),
            input_port("target_label", str, "", "The detection's class label (e.g. tag36h11); '': any."),
            message_output("detection_pose", POSE_STAMPED, "{detection_pose}", "The detection's pose."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.transforms import pose_from_message

        detections = read_message(self, "detections")
        target_id = int(read_input(self, "target_id"))
        label = read_text(self, "target_label").strip()
        candidates = []
        for detection in detections.detections:
            if target_id >= 0 and str(detection.id).strip() != str(target_id):
                continue
            for result in detection.results:
                if label and str(result.hypothesis.class_id) != label:
                    continue
                candidates.append((float(result.hypothesis.score), detection, result))
        if not candidates:
            seen = ", ".join(
                f"id {d.id!s} ({', '.join(str(r.hypothesis.class_id) for r in d.results) or 'no label'})"
                for d in detections.detections
            )
            wanted = (
                " and ".join(
                    part
                    for part in (
                        f"id {target_id}" if target_id >= 0 else "",
                        f"label {label!r}" if label else "",
                    )
                    if part
                )
                or "any id"
            )
            self.logger.publish_failure(
                f"GetDetectionPose: no detection with {wanted}; detections: {seen or 'none'}"
            )
            return NodeStatus.FAILURE
        _score, detection, result = max(candidates, key=lambda item: item[0])
        frame = str(detection.header.frame_id) or str(detections.header.frame_id)
        message = pose_stamped_message(frame, pose_from_message(result.pose.pose))
        message.header.stamp = detection.header.stamp
        self.set_output("detection_pose", message)
        return NodeStatus.SUCCESS
