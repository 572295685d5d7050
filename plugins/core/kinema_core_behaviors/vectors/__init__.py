"""Vectors: create, edit, read and iterate over blackboard vectors (of messages, numbers, strings)."""

from __future__ import annotations

from .add_pose_stamped_to_vector import AddPoseStampedToVector
from .edit_vector import InsertInVector, PushBackVector, RemoveFromVector, ReplaceInVector
from .for_each import ForEach, ForEachUntilSuccess
from .read_vector import GetElementOfVector, GetSizeOfVector
from .reset_vector import ResetPoseStampedVector, ResetVector
from .reverse_vector import ReversePoseStampedVector

BEHAVIORS = (
    ResetVector,
    ResetPoseStampedVector,
    PushBackVector,
    InsertInVector,
    RemoveFromVector,
    ReplaceInVector,
    GetElementOfVector,
    GetSizeOfVector,
    ForEach,
    ForEachUntilSuccess,
    AddPoseStampedToVector,
    ReversePoseStampedVector,
)
