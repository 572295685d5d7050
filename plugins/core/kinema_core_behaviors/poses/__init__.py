"""Poses: pose maths and frames (transforms between poses and frames, forward kinematics, averages)."""

from __future__ import annotations

from .average_pose_stamped import AveragePoseStamped, AveragePoseStampedVector
from .calculate_pose_offset import CalculatePoseOffset
from .compute_link_pose_forward_kinematics import ComputeLinkPoseForwardKinematics
from .is_pose_near_identity import IsPoseNearIdentity
from .transform_pose import TransformPose
from .transform_pose_frame import TransformPoseFrame
from .transform_pose_with_pose import TransformPoseWithPose

BEHAVIORS = (
    CalculatePoseOffset,
    ComputeLinkPoseForwardKinematics,
    TransformPose,
    TransformPoseFrame,
    TransformPoseWithPose,
    AveragePoseStamped,
    AveragePoseStampedVector,
    IsPoseNearIdentity,
)
