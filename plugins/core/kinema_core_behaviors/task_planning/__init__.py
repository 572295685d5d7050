"""Task planning: MoveIt Pro's MTC behaviors on Kinema's task planner (:mod:`kinema.motion.task`).

InitializeMTCTask creates a task, the SetupMTC* behaviors append stages, PlanMTCTask plans it into a
solution, and the core subtree "Execute MTC Solution" (or ConvertMtcSolutionToJointTrajectory and
ExecuteTrajectory) runs it. WaitForMTCSolutionApproval lives with the other approvals (ui).
"""

from __future__ import annotations

from .plan_task import ConvertMtcSolutionToJointTrajectory, PlanMTCTask
from .set_collision_rule import SetupMTCSetCollisionRule
from .setup_stages import (
    InitializeMTCTask,
    SetupMTCBatchPoseIK,
    SetupMTCConnectWithProRRT,
    SetupMTCCurrentState,
    SetupMTCFromSolution,
    SetupMTCMoveAlongFrameAxis,
    SetupMTCPlanToPose,
    SetupMTCPlanToRobotState,
)

BEHAVIORS = (
    ConvertMtcSolutionToJointTrajectory,
    InitializeMTCTask,
    PlanMTCTask,
    SetupMTCBatchPoseIK,
    SetupMTCConnectWithProRRT,
    SetupMTCCurrentState,
    SetupMTCFromSolution,
    SetupMTCMoveAlongFrameAxis,
    SetupMTCPlanToPose,
    SetupMTCPlanToRobotState,
    SetupMTCSetCollisionRule,
)
