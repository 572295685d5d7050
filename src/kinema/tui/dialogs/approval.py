"""Approve a planned motion: the question, the motion's steps (stage, duration, joints, gripper), ctrl+y/n."""

from __future__ import annotations

from rich.console import Group
from rich.table import Table
from rich.text import Text
from textual.app import ComposeResult
from textual.containers import Vertical
from textual.widgets import Static

from kinema.tui.connection import SolutionStep
from kinema.tui.dialogs.confirm import MotionQuestionDialog


def steps_table(steps: tuple[SolutionStep, ...], duration: float) -> Group:
    """One row per motion (or change between motions), then the whole duration and whether the gripper
    moves at all."""
    table = Table(box=None, pad_edge=False, expand=True, show_edge=False, header_style="bold dim")
    table.add_column("#", justify="right", no_wrap=True)
    table.add_column("Motion", no_wrap=True)
    table.add_column("Time", justify="right", no_wrap=True)
    table.add_column("Joints", justify="right", no_wrap=True)
    table.add_column("Gripper / change", ratio=1)
    for number, step in enumerate(steps, start=1):
        if step.note:
            table.add_row(str(number), step.stage, "", "", Text(step.note, style="italic"))
            continue
        table.add_row(
            str(number),
            step.stage,
            f"{step.duration:.2f} s",
            str(len(step.joint_names)),
            Text(step.gripper or "holds still", style="bold" if step.gripper else "dim"),
        )
    motions = [step for step in steps if not step.note]
    moves = sum(1 for step in motions if step.gripper)
    total = Text()
    plural = "s" if len(motions) != 1 else ""
    total.append(f"{len(motions)} motion{plural}, {duration:.2f} s in all", style="bold")
    total.append(
        f"; the gripper moves in {moves} of them" if moves else "; the gripper holds still throughout",
        style="dim",
    )
    total.append("\nkinema view draws the motion while this question is open.", style="dim")
    return Group(table, total)


class ApprovalDialog(MotionQuestionDialog):
    """A behavior's approval question with the planned motion it is about; returns True when approved."""

    def __init__(self, question: str, steps: tuple[SolutionStep, ...], duration: float) -> None:
        super().__init__(question)
        self.steps = steps
        self.duration = duration

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog wide"):
            yield from self.compose_question()
            yield Static(steps_table(self.steps, self.duration), id="approval-steps")
            yield from self.compose_buttons("success")
