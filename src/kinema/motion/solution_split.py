"""Splitting a planned task solution in two, at a sub-trajectory numbered as MoveIt Pro numbers them.

MoveIt Task Constructor's solution message holds one sub-trajectory per stage the solution passes
through, whether the stage moves or not: the current state (no motion), each collision-rule change, each
motion; MoveIt Pro's SetupMTCPlanToPose adds two stages (a connect motion, then the IK of the pose).
:func:`solution_entries` lists a Kinema :class:`~kinema.motion.task.TaskSolution` in that numbering, so
that MoveIt Pro objectives' indices (``SplitMTCSolution index="3"`` after a current state and a plan to
pose) pick the same stage. :func:`split_solution` cuts there; each half is a complete solution (its own
start and end), the second starts where the first ends, and the two run one after the other do what the
whole does.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from kinema.errors import MotionError
from kinema.motion.task import SceneChange, SubTrajectory, TaskSolution

# Stage types that are two stages in MoveIt Pro's solution: their motion, then a stage that only fixes a
# state (the IK of the pose).
TWO_ENTRY_STAGES = {"PlanToPose": "IK"}


@dataclass(frozen=True)
class SolutionEntry:
    """One sub-trajectory of a solution in MTC's numbering.

    Attributes:
        label: the stage's name (``plan to pose``; ``plan to pose: IK`` for the second of two).
        stage_index: the stage's place in the task (-1 when unknown).
        sub: its motion, or None (a state-fixing stage, a collision-rule change).
        change: its collision-rule change, or None.
    """

    label: str
    stage_index: int
    sub: SubTrajectory | None = None
    change: SceneChange | None = None


def solution_entries(solution: TaskSolution) -> list[SolutionEntry]:
    """The sub-trajectories of ``solution`` in MoveIt Pro's numbering (see the module docstring).

    A solution whose motions do not say which stage made them (built by hand) is numbered one entry per
    motion and collision-rule change.
    """
    events: list[SolutionEntry] = []
    for k, sub in enumerate([*solution.sub_trajectories, None]):
        events += [
            SolutionEntry(change.stage, change.stage_index, change=change)
            for change in solution.scene_changes
            if change.before == k
        ]
        if sub is not None:
            events.append(SolutionEntry(sub.stage, sub.stage_index, sub=sub))
    if not solution.reports or any(event.stage_index < 0 for event in events):
        return events
    entries: list[SolutionEntry] = []
    for report in solution.reports:
        own = [event for event in events if event.stage_index == report.index]
        entries += own
        second = TWO_ENTRY_STAGES.get(report.stage_type)
        if second:
            entries.append(SolutionEntry(f"{report.name}: {second}", report.index))
        elif not own:
            entries.append(SolutionEntry(report.name, report.index))
    return entries


def split_solution(solution: TaskSolution, index: int) -> tuple[TaskSolution, TaskSolution]:
    """``solution`` cut before entry ``index`` of :func:`solution_entries`: (entries before, entries from).

    Each half keeps the collision-rule changes and stage reports of its entries.

    Raises:
        MotionError: ``index`` leaves a half empty; the message lists the entries and the valid range.
    """
    entries = solution_entries(solution)
    if not 1 <= index <= len(entries) - 1:
        listing = ", ".join(f"{k}: {entry.label}" for k, entry in enumerate(entries))
        valid = f"1 to {len(entries) - 1}" if len(entries) > 1 else "none: it cannot be split"
        raise MotionError(
            f"index {index} is out of range: the solution of task {solution.task_id!r} has "
            f"{len(entries)} sub-trajectories ({listing}); valid indices (both halves non-empty): {valid}"
        )
    first = _part(solution, entries[:index], solution.start)
    second = _part(solution, entries[index:], first.end)
    return first, second


def _part(solution: TaskSolution, entries: list[SolutionEntry], start: np.ndarray) -> TaskSolution:
    column = {name: i for i, name in enumerate(solution.joint_names)}
    q = np.array(start, dtype=float)
    subs: list[SubTrajectory] = []
    changes: list[SceneChange] = []
    for entry in entries:
        if entry.change is not None:
            changes.append(replace(entry.change, before=len(subs)))
        if entry.sub is not None:
            trajectory = entry.sub.trajectory
            q[[column[n] for n in trajectory.joint_names]] = trajectory.positions[-1]
            subs.append(entry.sub)
    stages = {entry.stage_index for entry in entries}
    return TaskSolution(
        solution.task_id,
        solution.joint_names,
        np.array(start, dtype=float),
        q,
        tuple(subs),
        tuple(report for report in solution.reports if report.index in stages),
        solution.planning_seconds,
        tuple(changes),
    )
