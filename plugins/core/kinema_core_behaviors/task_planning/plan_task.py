"""PlanMTCTask plans a task into a solution; ConvertMtcSolutionToJointTrajectory makes it one trajectory."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from kinema.behaviors import (
    AsyncBehavior,
    FormerSpelling,
    NodeStatus,
    PortInfo,
    SyncBehavior,
    input_port,
    output_port,
)
from kinema.errors import KinemaError

from ..messages.conversions import trajectory_message
from ..motion.joint_states import joint_state_monitor
from ..motion.planned_trajectory import publish_planned_trajectory
from ..motion.planning_resources import collision_checker, robot_model
from ..poses.frame_tree import current_frame_tree
from .mtc_task import CurrentStateMarker, task_input
from .progress import TaskProgress
from .setup_stages import SUBCATEGORY

DEFAULT_PADDING = 0.01


def _stage_summary(reports: Any) -> str:
    marks = {"solved": "ok", "failed": "FAILED", "waiting": "-", "planning": "…"}
    return "; ".join(f"{r.index + 1}. {r.name}: {marks.get(r.status, r.status)}" for r in reports)


START_TOLERANCE = 0.01  # rad or m: how far the robot may be from a replayed solution's start


def _away_joints(model: Any, q: Any, solution: Any) -> list[str]:
    """The joints a replayed solution moves that are not where it starts."""
    moved = {n for sub in solution.sub_trajectories for n in sub.trajectory.joint_names}
    return [
        n
        for i, n in enumerate(model.joint_names)
        if n in moved and abs(q[i] - solution.start[i]) > START_TOLERANCE
    ]


def _away_from(model: Any, q: Any, solution: Any) -> str:
    """The joints a replayed solution moves that are not where it starts ('' when all are)."""
    index = {n: i for i, n in enumerate(model.joint_names)}
    off = [
        f"{n} at {q[index[n]]:.3f}, not {solution.start[index[n]]:.3f}"
        for n in _away_joints(model, q, solution)
    ]
    return ", ".join(off[:3]) + (f" and {len(off) - 3} more" if len(off) > 3 else "")


def _group_moving(behavior: Any, model: Any, q: Any, solution: Any) -> str:
    """The planning group that moves every joint not yet where ``solution`` starts: the config's own when
    it does, else the smallest such group.

    Raises:
        KinemaError: no group holds them all.
    """
    moved = set(_away_joints(model, q, solution))
    cell = behavior.context.cell
    preferred = cell.planning_group if cell is not None else None
    fitting = sorted(
        (len(group.joint_names), name)
        for name, group in model.groups.items()
        if moved <= set(group.joint_names)
    )
    if preferred and any(name == preferred for _size, name in fitting):
        return str(preferred)
    if not fitting:
        raise KinemaError(
            f"the robot is not where the replayed solution starts, and no planning group moves every joint "
            f"that is elsewhere ({', '.join(sorted(moved))}) to get there"
        )
    return fitting[0][1]


class PlanMTCTask(AsyncBehavior):
    """Plans ``task`` from the robot's current state into ``solution``, against the planning scene.

    Poses are resolved in the frames of the cell when planning starts (robot links at the current state,
    simulated objects, scene objects). The planned motion is published for ``kinema view``, which also
    draws the tool's path of each stage as a coloured line, and the stages' outcome is logged. While it
    plans, each stage's state (waiting, planning, solved, failed) and time are published on
    ``/kinema/task_planning`` for the TUI's task panel. A failure
    names the stage and why (no IK for pose 2 of 3, the Cartesian path stopped at 43 %, no path within the
    planning time).
    """

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("task", None, "{mtc_task}", "The task to plan (InitializeMTCTask, SetupMTC*)."),
            output_port("solution", None, "{mtc_solution}", "The planned solution."),
            input_port(
                "max_solutions",
                int,
                1,
                "How many solutions to look for; Kinema returns the first that plans.",
            ),
        ]

    def do_work(self) -> bool:
        try:
            mtc = task_input(self)
        except KinemaError as error:
            return self._fail(str(error))
        with TaskProgress(self, mtc.task_id, self.full_path) as progress:
            return self._plan(mtc, progress)

    def _plan(self, mtc: Any, progress: TaskProgress) -> bool:
        from kinema.motion.task import Task, TaskPlanningError, plan_task
        from kinema.motion.task_stages import Connect, CurrentState, FromSolution, MotionSettings

        try:
            if int(self.get_input("max_solutions")) < 1:
                return self._fail(
                    f"max_solutions must be at least 1, got {self.get_input('max_solutions')}", progress
                )
            model = robot_model(self.context, "PlanMTCTask")
            q = joint_state_monitor(self.context, "PlanMTCTask").current_positions(
                model.joint_names, self.context.clock
            )
            tree = current_frame_tree(self)
            robot_frames = {frame.name for frame in model.pin_model.frames}
            fixed = {n: tree.world_T(n) for n in tree.names() if n not in robot_frames and n != "world"}
            stages = [CurrentState(q) if isinstance(s, CurrentStateMarker) else s for s in mtc.stages]
            if stages and isinstance(stages[0], FromSolution):
                away = _away_from(model, q, stages[0].solution)
                if away:
                    # Replaying a stored solution from elsewhere (MoveIt Pro's "Stitch Multiple Point
                    # Clouds Together" replays its first plan after visiting every viewpoint): move to its
                    # start first, collision-free, rather than jump there.
                    self.logger.publish_info(
                        f"PlanMTCTask: the robot is not where the solution of {stages[0].name!r} starts "
                        f"({away}); a collision-free move there comes first"
                    )
                    connect = Connect(
                        MotionSettings(group=_group_moving(self, model, q, stages[0].solution)),
                        name="move to the solution's start",
                    )
                    stages = [CurrentState(q), connect, *stages]
            checker = collision_checker(self.context, "PlanMTCTask", DEFAULT_PADDING)
            solution = plan_task(
                Task(mtc.task_id, stages),
                checker,
                frames=fixed,
                stop=self.stop_requested,
                progress=progress.update,
                timeout=mtc.timeout if mtc.timeout > 0 else None,
            )
        except TaskPlanningError as error:
            self.logger.publish_info(f"PlanMTCTask: stages: {_stage_summary(error.reports)}")
            progress.finish("failed", error.reports, str(error))
            return self._fail(str(error))
        except KinemaError as error:
            return self._fail(str(error), progress)
        progress.finish("solved", solution.reports)
        self.logger.publish_info(
            f"PlanMTCTask: planned task {mtc.task_id!r} in {solution.planning_seconds:.2f} s: "
            f"{_stage_summary(solution.reports)}"
        )
        self.set_output("solution", solution)
        publish_planned_trajectory(self, trajectory_message(solution.joined()))
        publish_stage_paths(self, solution, model)
        return True

    def _fail(self, reason: str, progress: TaskProgress | None = None) -> bool:
        if progress is not None:
            progress.finish("failed", (), reason)
        self.logger.publish_failure(f"PlanMTCTask: planning failed: {reason}")
        return False


STAGE_COLORS = ((0.1, 0.6, 1.0), (1.0, 0.6, 0.1), (0.2, 0.8, 0.3), (0.9, 0.2, 0.6), (0.6, 0.4, 1.0))
STAGE_PATHS_NAMESPACE = "mtc_solution"
MAX_STAGE_LINES = 32


def publish_stage_paths(behavior: Any, solution: Any, model: Any, frames: Sequence[str] = ()) -> None:
    """Draw the path of ``frames`` during each stage in ``kinema view`` (one coloured line per moving stage
    and frame).

    Without ``frames`` the tool is the tip link of the first moving stage's group (``grasp_link`` on
    lab_sim). Only for display: without a transport node nothing is published.
    """
    if behavior.context.node is None or not solution.sub_trajectories:
        return
    if not frames:
        first = solution.sub_trajectories[0].trajectory.joint_names
        group = next((g for g in model.groups.values() if tuple(g.joint_names) == tuple(first)), None)
        frames = [getattr(group, "tip_link", None) or model.link_names[-1]]
    paths = [
        (stage if len(frames) == 1 else f"{stage}: {frame}", points)
        for frame in frames
        for stage, points in solution.tool_paths(model, frame)
    ]
    publish_paths(behavior, paths)


def publish_paths(behavior: Any, paths: Sequence[tuple[str, Any]]) -> None:
    """Draw ``(label, points (N, 3) in the world)`` lines in ``kinema view`` under the solution namespace,
    removing the lines of an earlier, longer drawing (the user's own markers stay)."""
    from kinema.transport import from_dict

    from ..ui.visualize_pose import MARKER_ARRAY_TYPE, marker_publisher

    node = behavior.context.node
    if node is None:
        return
    markers: list[dict[str, Any]] = []
    for index, (label, points) in enumerate(paths):
        if len(points) < 2:
            continue
        r, g, b = STAGE_COLORS[index % len(STAGE_COLORS)]
        markers.append(
            {
                "header": {"frame_id": "world"},
                "ns": STAGE_PATHS_NAMESPACE,
                "id": index + 1,
                "type": 4,  # LINE_STRIP
                "action": 0,
                "pose": {"orientation": {"w": 1.0}},
                "scale": {"x": 0.005},
                "color": {"r": r, "g": g, "b": b, "a": 1.0},
                "points": [{"x": float(x), "y": float(y), "z": float(z)} for x, y, z in points],
                "text": label,
            }
        )
    drawn = {m["id"] for m in markers}
    markers += [
        {"header": {"frame_id": "world"}, "ns": STAGE_PATHS_NAMESPACE, "id": i, "action": 2}
        for i in range(1, max(MAX_STAGE_LINES, len(paths)) + 1)
        if i not in drawn
    ]
    marker_publisher(behavior, node).publish(from_dict(MARKER_ARRAY_TYPE, {"markers": markers}))


class ConvertMtcSolutionToJointTrajectory(SyncBehavior):
    """Joins the motions of ``solution`` into one ``trajectory_msgs/JointTrajectory``.

    The stages' motions follow one another (each starts where the previous ended, at rest).
    """

    subcategory = SUBCATEGORY
    # MoveIt Pro's former ExecuteMTCTask behavior is the core "Execute MTC Solution" subtree today, which
    # is built on this behavior.
    former_spellings = (FormerSpelling("ExecuteMTCTask", current_id="Execute MTC Solution", subtree=True),)

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("solution", None, "{mtc_solution}", "A solution PlanMTCTask planned."),
            output_port(
                "joint_trajectory",
                None,
                "{joint_trajectory_msg}",
                "The whole motion (trajectory_msgs/JointTrajectory).",
            ),
        ]

    def tick(self) -> NodeStatus:
        from kinema.motion.task import TaskSolution

        solution = self.get_input_or("solution", None)
        if not isinstance(solution, TaskSolution):
            got = "nothing" if solution is None else type(solution).__name__
            self.logger.publish_failure(
                f"ConvertMtcSolutionToJointTrajectory: port [solution] needs a solution PlanMTCTask "
                f"planned, got {got}"
            )
            return NodeStatus.FAILURE
        try:
            joined = solution.joined()
        except KinemaError as error:
            self.logger.publish_failure(f"ConvertMtcSolutionToJointTrajectory: {error}")
            return NodeStatus.FAILURE
        self.set_output("joint_trajectory", trajectory_message(joined))
        return NodeStatus.SUCCESS
