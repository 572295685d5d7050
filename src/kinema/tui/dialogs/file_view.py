"""A package's file, read-only, with YAML, XML and Python colours (the Configs screen's Files tab)."""

from __future__ import annotations

from pathlib import Path

from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Vertical
from textual.screen import ModalScreen
from textual.widgets import Label, TextArea

LANGUAGES = {".yaml": "yaml", ".yml": "yaml", ".xml": "xml", ".urdf": "xml", ".srdf": "xml", ".py": "python"}


class FileViewDialog(ModalScreen[None]):
    """Shows ``text`` (the content of ``path``); Escape closes it."""

    BINDINGS = [Binding("escape", "close", "Close", id="file.close", tooltip="Back to the files")]

    def __init__(self, path: Path, text: str) -> None:
        super().__init__()
        self.path = path
        self.text = text

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog wide file-view"):
            yield Label(str(self.path), classes="dialog-title")
            language = LANGUAGES.get(self.path.suffix.lower())
            try:
                area = TextArea(self.text, language=language, read_only=True, id="file-text")
            except Exception:  # no highlighting for this language here: plain text reads as well
                area = TextArea(self.text, read_only=True, id="file-text")
            yield area
            yield Label(
                "Esc closes · read-only: edit the file in your editor (hot reload picks it up)",
                classes="dialog-keys",
            )

    def on_mount(self) -> None:
        self.set_focus(self.query_one(TextArea))

    def action_close(self) -> None:
        self.dismiss(None)
