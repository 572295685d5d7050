"""AveragePoseStamped and AveragePoseStampedVector: the mean of noisy pose samples (tag detections,
calibration results)."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import KinemaError

from ..messages.conversions import POSE_STAMPED_TYPE, pose_matrix, pose_stamped_message
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    message_output,
    port_error,
    read_input,
    read_message,
    read_vector,
)


def _mean(node: Any, port: str, frames_and_poses: list[tuple[str, Any]]) -> Any:
    """The PoseStamped mean of ``(frame, 4x4)`` samples that share one frame."""
    from kinema.transforms import average_pose

    frames = sorted({frame for frame, _ in frames_and_poses})
    if len(frames) > 1:
        raise port_error(
            node,
            port,
            f"holds poses in frames {', '.join(repr(f) for f in frames)}",
            "bring them into one frame first (TransformPoseFrame)",
        )
    return pose_stamped_message(frames[0], average_pose([pose for _, pose in frames_and_poses]))


class AveragePoseStamped(SyncBehavior):
    """Adds ``pose_sample`` to the samples this node has seen and writes their mean to ``avg_pose``.

    Tick it once per new sample (in a Repeat, as MoveIt Pro's "Sample April Tag" does): the first
    ``num_samples`` samples are averaged; the sample after them starts a new average, unless
    ``run_continuously``, which keeps the mean of the latest ``num_samples`` (a moving average). A sample
    further than ``max_distance`` (m) or turned more than ``max_rotation`` (rad) from the mean so far is
    an outlier: the behavior fails, naming how far off it is, and the sample is not kept. Samples must
    share one frame. The mean is the mean position and the rotation closest to the mean rotation. (MoveIt
    Pro's defaults and its handling of an outlier are not public; these are Kinema's.)
    """

    subcategory = "Math - Poses"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("pose_sample", POSE_STAMPED_TYPE, "{pose_sample}", "The new sample."),
            message_output("avg_pose", POSE_STAMPED_TYPE, "{avg_pose}", "The mean of the samples kept."),
            input_port("num_samples", int, 10, "How many samples make one average."),
            input_port("max_distance", float, 0.05, "Largest distance (m) of a sample from the mean so far."),
            input_port("max_rotation", float, 0.5, "Largest angle (rad) of a sample from the mean so far."),
            input_port(
                "run_continuously",
                bool,
                False,
                "Keep a moving average of the latest num_samples instead of starting over after them.",
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        from kinema.transforms import angle_between, average_pose, quaternion_from_matrix

        count = int(read_input(self, "num_samples"))
        if count < 1:
            raise port_error(self, "num_samples", f"= {count}", "give 1 or more")
        max_distance, max_rotation = (
            float(read_input(self, "max_distance")),
            float(read_input(self, "max_rotation")),
        )
        for port, value in (("max_distance", max_distance), ("max_rotation", max_rotation)):
            if not value >= 0:
                raise port_error(self, port, f"= {value:g}", "give a bound >= 0")
        try:
            frame, sample = pose_matrix(read_message(self, "pose_sample"), "pose_sample")
        except KinemaError as error:
            raise port_error(self, "pose_sample", str(error)) from None
        samples: list[tuple[str, Any]] = getattr(self, "_samples", [])
        continuous = bool(read_input(self, "run_continuously"))
        if len(samples) >= count and not continuous:
            samples = []  # the last average is complete: this sample starts the next one
        if samples:
            if frame != samples[0][0]:
                raise port_error(
                    self,
                    "pose_sample",
                    f"is in frame {frame!r}, the samples so far in {samples[0][0]!r}",
                    "give every sample in one frame",
                )
            mean = average_pose([pose for _, pose in samples])
            distance = float(np.linalg.norm(sample[:3, 3] - mean[:3, 3]))
            angle = angle_between(quaternion_from_matrix(mean), quaternion_from_matrix(sample))
            if distance > max_distance or angle > max_rotation:
                self.logger.publish_failure(
                    f"AveragePoseStamped: the sample is {distance:.4f} m and {angle:.3f} rad from the mean "
                    f"of {len(samples)} samples (max_distance {max_distance:g} m, max_rotation "
                    f"{max_rotation:g} rad); it is left out"
                )
                self._samples = samples
                return NodeStatus.FAILURE
        samples = [*samples, (frame, sample)][-count:]
        self._samples = samples
        self.set_output("avg_pose", _mean(self, "pose_sample", samples))
        return NodeStatus.SUCCESS


class AveragePoseStampedVector(SyncBehavior):
    """Writes the mean of the poses in ``pose_stamped_vector`` (all in one frame) to
    ``average_pose_stamped``: the mean position and the rotation closest to the mean rotation. Fails on an
    empty vector or poses in different frames."""

    subcategory = "Math - Poses"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "pose_stamped_vector",
                None,
                "{pose_stamped_vector}",
                "The poses (a vector of geometry_msgs/PoseStamped).",
            ),
            message_output(
                "average_pose_stamped", POSE_STAMPED_TYPE, "{average_pose_stamped}", "Their mean."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        poses = read_vector(self, "pose_stamped_vector")
        if not poses:
            raise port_error(self, "pose_stamped_vector", "is an empty vector", "add poses first")
        samples = []
        for index, pose in enumerate(poses):
            try:
                samples.append(pose_matrix(pose, f"pose_stamped_vector[{index}]"))
            except KinemaError as error:
                raise port_error(self, "pose_stamped_vector", str(error)) from None
        self.set_output("average_pose_stamped", _mean(self, "pose_stamped_vector", samples))
        return NodeStatus.SUCCESS
