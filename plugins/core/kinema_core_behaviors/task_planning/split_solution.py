"""SplitMTCSolution: cut a planned solution in two, to execute its halves separately."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port
from kinema.errors import KinemaError

from .setup_stages import SUBCATEGORY


class SplitMTCSolution(SyncBehavior):
    """Splits ``solution_in`` into the sub-trajectories before ``index`` and those from ``index`` on.

    Sub-trajectories are numbered as MoveIt Pro's solution numbers them: one per stage the task passed
    through, moving or not (0 the current state; 1 and 2 a SetupMTCPlanToPose, which is a connect motion
    and an IK stage there; then one per later stage, a collision-rule change included). So MoveIt Pro's
    "Push Button" (current state, plan to pose, move along frame axis) splits at 3 into the motion to the
    button and the push. Each half is a solution of its own for 'Execute MTC Solution',
    ConvertMtcSolutionToJointTrajectory, WaitForMTCSolutionApproval or SetupMTCFromSolution; the second
    starts where the first ends. Fails, listing the sub-trajectories and the valid range, when ``index``
    would leave a half empty, and when ``solution_in`` is no solution PlanMTCTask planned.
    """

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("solution_in", None, "{mtc_solution}", "A solution PlanMTCTask planned."),
            input_port(
                "index",
                int,
                1,
                "The first sub-trajectory of the second half (MoveIt Pro's numbering, from 0), 1 to the "
                "number of sub-trajectories - 1.",
            ),
            output_port("solution_out_1", None, "{solution_out_1}", "The sub-trajectories before index."),
            output_port(
                "solution_out_2", None, "{solution_out_2}", "The sub-trajectories from index to the end."
            ),
        ]

    def tick(self) -> NodeStatus:
        from kinema.motion.solution_split import split_solution
        from kinema.motion.task import TaskSolution

        solution = self.get_input_or("solution_in", None)
        if not isinstance(solution, TaskSolution):
            got = "nothing" if solution is None else type(solution).__name__
            self.logger.publish_failure(
                f"SplitMTCSolution: port [solution_in] needs a solution PlanMTCTask planned, got {got}"
            )
            return NodeStatus.FAILURE
        try:
            first, second = split_solution(solution, int(self.get_input("index")))
        except KinemaError as error:
            self.logger.publish_failure(f"SplitMTCSolution: port [index]: {error}")
            return NodeStatus.FAILURE
        self.set_output("solution_out_1", first)
        self.set_output("solution_out_2", second)
        return NodeStatus.SUCCESS
