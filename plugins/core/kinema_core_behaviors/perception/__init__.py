"""Perception: camera messages from topics and what is found in them (AprilTags)."""

from __future__ import annotations

from .apriltags import DetectAprilTags, GetDetectionPose
from .topic_messages import GetCameraInfo, GetImage, GetPointCloud

BEHAVIORS = (GetImage, GetCameraInfo, GetPointCloud, DetectAprilTags, GetDetectionPose)
