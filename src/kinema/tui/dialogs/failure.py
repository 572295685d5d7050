"""The whole message of a failed or cancelled run, wrapped and scrollable (ctrl+o)"""

from __future__ import annotations

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Vertical, VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Label, Static

from kinema.tui.run_outcome import RunOutcome, failure_text


def outcome_text(outcome: RunOutcome) -> Text:
    """The exception (or the node's message) first, then the runtime's notes, then where it happened."""
    explained = failure_text(outcome.message)
    failed = outcome.outcome == "Failure"
    text = Text()
    text.append(explained.headline, style="bold red" if failed else "bold yellow")
    # A note (older code runs: its file did not load) changes what the exception means: before the path.
    for note in explained.notes:
        text.append("\nnote: ", style="bold yellow")
        text.append(note, style="yellow")
    if explained.where:
        text.append("\nat ", style="dim")
        text.append(explained.where)
    return text


class FailureDialog(ModalScreen[None]):
    """Shows one run's message whole; Escape, Enter or q closes it."""

    BINDINGS = [Binding("escape,enter,q", "close", "Close", id="failure.close", tooltip="Back to the tree")]

    def __init__(self, outcome: RunOutcome) -> None:
        super().__init__()
        self.outcome = outcome

    def compose(self) -> ComposeResult:
        how = "failed" if self.outcome.outcome == "Failure" else "was cancelled"
        with Vertical(classes="dialog wide"):
            yield Label(f"{self.outcome.objective_name} {how}", classes="dialog-title")
            with VerticalScroll(id="failure-full"):
                yield Static(outcome_text(self.outcome))
                yield Static(Text("\nAs the runtime wrote it:\n", style="dim") + Text(self.outcome.message))
            yield Label("Esc, Enter or q closes", classes="dialog-keys")

    def action_close(self) -> None:
        self.dismiss(None)
