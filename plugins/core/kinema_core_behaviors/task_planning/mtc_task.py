"""The MTC task and solution values behaviors pass on the blackboard (``{mtc_task}``, ``{mtc_solution}``).

A task is built by InitializeMTCTask and the SetupMTC* behaviors, then planned by PlanMTCTask. The
SetupMTC* behaviors record what each stage asks for; frames and the current state are read when the task
is planned (as MoveIt Task Constructor does), so a pose in ``grasp_link`` means the grasp link where the
robot is when planning starts.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from kinema.errors import ObjectiveError


class CurrentStateMarker:
    """Stands for the robot's state when the task is planned (SetupMTCCurrentState)."""

    name = "current state"


@dataclass
class MtcTask:
    """A task being set up: its id, planning timeout and stages (kinema.motion stages or markers)."""

    task_id: str
    timeout: float = -1.0
    stages: list[Any] = field(default_factory=list)

    def __repr__(self) -> str:
        return (
            f"MtcTask({self.task_id!r}, {len(self.stages)} stages: {', '.join(s.name for s in self.stages)})"
        )


def task_input(behavior: Any) -> MtcTask:
    """The ``task`` port's value.

    Raises:
        ObjectiveError: no task there (InitializeMTCTask must run first).
    """
    value = behavior.get_input_or("task", None)
    if not isinstance(value, MtcTask):
        got = "nothing" if value is None else type(value).__name__
        raise ObjectiveError(
            f"{behavior.registration_id}: port [task] needs the task InitializeMTCTask creates, got {got}"
        )
    return value


def stage_name(task: MtcTask, base: str) -> str:
    """``base``, numbered when the task already has a stage of that name (``approach``, ``approach 2``)."""
    names = {s.name for s in task.stages}
    if base not in names:
        return base
    n = 2
    while f"{base} {n}" in names:
        n += 1
    return f"{base} {n}"
