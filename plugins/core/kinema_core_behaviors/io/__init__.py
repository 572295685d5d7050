"""I/O: topics and services (Trigger calls, string publishing) and recording joint trajectories."""

from __future__ import annotations

from .call_trigger_service import CallTriggerService
from .publish_string import PublishString
from .record_joint_trajectory import RecordJointTrajectory

BEHAVIORS = (CallTriggerService, PublishString, RecordJointTrajectory)
