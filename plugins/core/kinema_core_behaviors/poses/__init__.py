"""Poses: pose maths and frames (transforms between poses and frames, forward kinematics)."""

from __future__ import annotations

from .transform_pose import TransformPose

BEHAVIORS = (TransformPose,)
