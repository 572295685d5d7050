"""Files: load and save poses, joint states and trajectories as YAML, text and images.

Paths resolve as MoveIt Pro resolves them (:mod:`.locations`); every save is atomic.
"""

from __future__ import annotations

from .image_file import LoadImageFromFile, SaveImageToFile
from .save_pose_for_urdf import SavePoseForUrdf
from .text_file import ReadTextFileAsString
from .yaml_messages import (
    LoadJointTrajectoryFromYaml,
    LoadPoseStampedFromYaml,
    LoadPoseStampedVectorFromYaml,
    LoadRobotJointStateFromYaml,
    SaveJointTrajectoryToYaml,
    SavePoseStampedToYaml,
    SavePoseStampedVectorToYaml,
    SaveRobotJointStateToYaml,
)

BEHAVIORS = (
    LoadPoseStampedFromYaml,
    LoadPoseStampedVectorFromYaml,
    SavePoseStampedToYaml,
    SavePoseStampedVectorToYaml,
    LoadJointTrajectoryFromYaml,
    SaveJointTrajectoryToYaml,
    LoadRobotJointStateFromYaml,
    SaveRobotJointStateToYaml,
    ReadTextFileAsString,
    LoadImageFromFile,
    SaveImageToFile,
    SavePoseForUrdf,
)
