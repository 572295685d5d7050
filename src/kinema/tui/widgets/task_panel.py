"""The task panel: the stages of the task PlanMTCTask plans, with their state and time, live."""

from __future__ import annotations

from rich.console import Group
from rich.table import Table
from rich.text import Text
from textual.widgets import Static

from kinema.tui.connection import TaskPlanning

STATE_MARKS = {
    "waiting": ("·", "dim"),
    "planning": ("⟳", "bold yellow"),
    "solved": ("✔", "green"),
    "failed": ("✘", "bold red"),
}
TASK_STYLE = {"planning": "bold yellow", "solved": "bold green", "failed": "bold red"}


def task_table(task: TaskPlanning) -> Group:
    """A title line (task, state, time), one row per stage (name, type, state, time, note), and the full
    reason of a failed stage."""
    title = Text()
    title.append("Task ", style="bold")
    title.append(task.task_id or "(unnamed)", style="bold")
    title.append(f"  {task.state}", style=TASK_STYLE.get(task.state, ""))
    title.append(f"  {task.seconds:.2f} s", style="dim")
    if task.node_path:
        title.append(f"  {task.node_path}", style="dim")
    table = Table(box=None, pad_edge=False, expand=True, show_edge=False, header_style="bold dim")
    table.add_column("#", justify="right", no_wrap=True)
    table.add_column("Stage", no_wrap=True)
    table.add_column("Type", no_wrap=True, style="dim")
    table.add_column("State", no_wrap=True)
    table.add_column("Time", justify="right", no_wrap=True)
    table.add_column("Note", ratio=1, no_wrap=True, overflow="ellipsis")
    for number, stage in enumerate(task.stages, start=1):
        mark, style = STATE_MARKS.get(stage.state, ("?", ""))
        table.add_row(
            str(number),
            Text(stage.name),
            stage.type,
            Text(f"{mark} {stage.state}", style=style),
            f"{stage.seconds:.3f} s" if stage.state != "waiting" or stage.seconds else "",
            Text("" if stage.state == "failed" else stage.comment, style="dim"),
        )
    # Why a stage failed is the one thing worth reading in full: below the table, at full width.
    reasons = [
        Text(f"✘ {number}. {stage.name}: {stage.comment}", style="red")
        for number, stage in enumerate(task.stages, start=1)
        if stage.state == "failed" and stage.comment
    ]
    return Group(title, table, *reasons)


class TaskPanel(Static):
    """Shows a :class:`TaskPlanning`; hidden until a task is planned in the current run."""

    # (not ``task``: Textual's MessagePump.task is the widget's asyncio task)
    planning: TaskPlanning | None = None

    def show_task(self, task: TaskPlanning | None) -> None:
        """Show ``task`` (None hides the panel)."""
        self.planning = task
        self.set_class(task is not None, "shown")
        self.set_class(task is not None and task.state == "failed", "failed")
        self.update(task_table(task) if task is not None else "")
