"""Task planning: MoveIt Pro's MTC behaviors on Kinema's task planner (:mod:`kinema.motion.task`).

InitializeMTCTask creates a task, the SetupMTC* behaviors append stages, PlanMTCTask plans it into a
solution, and the core subtree "Execute MTC Solution" or ExecuteMTCSolution (or
ConvertMtcSolutionToJointTrajectory and ExecuteTrajectory) runs it; SplitMTCSolution cuts a solution in
two to run its halves separately. WaitForMTCSolutionApproval lives with the other approvals (ui).
"""

from __future__ import annotations

from .execute_solution import ExecuteMTCSolution
from .plan_task import ConvertMtcSolutionToJointTrajectory, PlanMTCTask
from .set_collision_rule import SetupMTCSetCollisionRule
from .setup_stages import (
    InitializeMTCTask,
    SetupMTCBatchPoseIK,
    SetupMTCCartesianMoveToRobotState,
    SetupMTCConnectWithProRRT,
    SetupMTCCurrentState,
    SetupMTCFromSolution,
    SetupMTCMoveAlongFrameAxis,
    SetupMTCPlanToPose,
    SetupMTCPlanToRobotState,
)
from .split_solution import SplitMTCSolution

BEHAVIORS = (
    ConvertMtcSolutionToJointTrajectory,
    ExecuteMTCSolution,
    InitializeMTCTask,
    PlanMTCTask,
    SetupMTCBatchPoseIK,
    SetupMTCCartesianMoveToRobotState,
    SetupMTCConnectWithProRRT,
    SetupMTCCurrentState,
    SetupMTCFromSolution,
    SetupMTCMoveAlongFrameAxis,
    SetupMTCPlanToPose,
    SetupMTCPlanToRobotState,
    SetupMTCSetCollisionRule,
    SplitMTCSolution,
)
