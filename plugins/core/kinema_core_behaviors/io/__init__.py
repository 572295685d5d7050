"""I/O: topics and services (Trigger calls, string and empty messages, frames on /tf) and recording joint
trajectories."""

from __future__ import annotations

from .call_trigger_service import CallTriggerService
from .publish_empty import PublishEmpty
from .publish_string import PublishString
from .publish_tf import PublishTF
from .record_joint_trajectory import RecordJointTrajectory

BEHAVIORS = (CallTriggerService, PublishString, RecordJointTrajectory, PublishEmpty, PublishTF)
