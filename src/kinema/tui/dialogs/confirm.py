"""Ask a yes/no question (delete a waypoint, quit): y confirms, n or Escape declines; the dialog says so."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.screen import ModalScreen
from textual.widgets import Button, Label


class ConfirmDialog(ModalScreen[bool]):
    """Returns True when confirmed. The focus starts on the decline button, so Enter alone declines."""

    BINDINGS = [
        Binding("y", "answer(True)", "Yes", id="dialog.yes", tooltip="Confirm"),
        Binding("n,escape", "answer(False)", "No", id="dialog.no", tooltip="Decline"),
    ]
    #: The keys as the dialog writes them: (confirm, decline).
    KEYS = ("y", "n or Esc")

    def __init__(self, question: str, confirm_label: str = "Yes", decline_label: str = "Cancel") -> None:
        super().__init__()
        self.question = question
        self.confirm_label = confirm_label
        self.decline_label = decline_label

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog"):
            yield from self.compose_question()
            yield from self.compose_buttons("error")

    def compose_question(self) -> ComposeResult:
        yield Label(self.question, classes="dialog-title")

    def compose_buttons(self, variant: str) -> ComposeResult:
        confirm, decline = self.KEYS
        yield Label(
            f"{confirm}: {self.confirm_label}    {decline}: {self.decline_label}", classes="dialog-keys"
        )
        with Horizontal(classes="dialog-buttons"):
            yield Button(f"{self.confirm_label} ({confirm})", variant=variant, id="yes")  # type: ignore[arg-type]
            yield Button(f"{self.decline_label} ({decline})", id="no")

    def on_mount(self) -> None:
        self.set_focus(self.query_one("#no", Button))

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.dismiss(event.button.id == "yes")

    def action_answer(self, answer: bool) -> None:
        self.dismiss(answer)


class MotionQuestionDialog(ConfirmDialog, inherit_bindings=False):
    """A question whose yes lets the robot move (approve a motion, resume at a breakpoint).

    No printable key approves: a word typed into the wrong window must not move the arm. ctrl+y (or the
    button) approves; n or Escape declines.
    """

    BINDINGS = [
        Binding("ctrl+y", "answer(True)", "Approve", id="dialog.approve", tooltip="Let the robot move"),
        Binding("n,escape", "answer(False)", "Reject", id="dialog.reject", tooltip="Decline"),
    ]
    KEYS = ("ctrl+y", "n or Esc")

    def __init__(self, question: str, confirm_label: str = "Approve", decline_label: str = "Reject") -> None:
        super().__init__(question, confirm_label, decline_label)

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog"):
            yield from self.compose_question()
            yield from self.compose_buttons("success")
