"""ExecuteMTCSolution: execute a solution PlanMTCTask planned, as one behavior."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import PortInfo, input_port
from kinema.errors import ObjectiveError

from ..messages.conversions import trajectory_message
from ..motion.execute_trajectory import ExecuteTrajectory
from .setup_stages import SUBCATEGORY

# ExecuteTrajectory's ports that carry over: those MoveIt Pro's objectives set on ExecuteMTCSolution, and
# the two tolerances (0: the controller's). The admittance ports are the jtac pipeline's: not declared.
_SHARED_PORTS = (
    "controller_action_name",
    "goal_duration_tolerance",
    "execution_pipeline",
    "goal_position_tolerance",
    "path_position_tolerance",
)


class ExecuteMTCSolution(ExecuteTrajectory):
    """Joins the stage motions of ``solution`` into one trajectory (each starting where the one before
    ended, at rest) and runs it on the FollowJointTrajectory controller of ``controller_action_name``,
    activating that controller first when it is inactive, as ExecuteTrajectory does.

    MoveIt Pro's newer objectives call it where older ones called the "Execute MTC Solution" subtree
    (hangar_sim's "Move to Pose No Preview"). Fails when ``solution`` is not a solution PlanMTCTask
    planned, or the controller rejects or aborts the motion.
    """

    subcategory = SUBCATEGORY
    description = "Execute a solution PlanMTCTask planned on the trajectory controller."
    former_spellings = ()

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        shared = [port for port in super().provided_ports() if port.name in _SHARED_PORTS]
        return [input_port("solution", None, "{mtc_solution}", "A solution PlanMTCTask planned."), *shared]

    async def do_work(self) -> bool:
        solution = self.get_input_or("solution", None)
        if solution is not None and not getattr(solution, "sub_trajectories", True):
            # A split before the first motion (SplitMTCSolution index 1 after a current state) leaves a half
            # that moves nothing: done, nothing sent (a hold of every joint, the gripper's too, was refused).
            self.logger.publish_info(f"{self.registration_id}: the solution moves nothing; nothing sent")
            return True
        return await super().do_work()

    def trajectory_to_run(self) -> Any:
        from kinema.motion.task import TaskSolution

        solution = self.get_input_or("solution", None)
        if not isinstance(solution, TaskSolution):
            got = "nothing" if solution is None else type(solution).__name__
            raise ObjectiveError(f"port [solution] needs a solution PlanMTCTask planned, got {got}")
        return trajectory_message(solution.joined())

    def admittance_fields(self) -> dict[str, Any] | None:
        return None  # no admittance ports: the jtc pipeline
