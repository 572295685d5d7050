"""The footer of key bindings, rebuilt only when the keys it shows change."""

from __future__ import annotations

from typing import Any

from textual.app import ComposeResult
from textual.screen import Screen
from textual.widgets import Footer
from textual.widgets._footer import FooterKey


class KeyFooter(Footer):
    """Textual's :class:`~textual.widgets.Footer`, skipping rebuilds that would show the same keys.

    Textual's footer removes and mounts all its keys again whenever a screen says its bindings may have
    changed: each widget mounted with bindings, each focus change. On the way to the first frame that was
    three rebuilds of the same nine keys, a third of the widgets the first screen mounted.

    Its keys also start as wide or compact as the footer: Textual's start compact and are bound to the
    footer's ``compact``, which restyled each key twice on mount (class ``-compact`` given, then taken).
    """

    _built_from: list[Any] | None = None

    def compose(self) -> ComposeResult:
        self._built_from = _bindings(self.screen) if self._bindings_ready else None
        for widget in super().compose():
            # Only the keys bound to the footer's compact (data_bind): the command palette's stays compact.
            if isinstance(widget, FooterKey) and "compact" in (widget._reactive_connect or {}):
                widget.set_reactive(FooterKey.compact, self.compact)
            yield widget

    def bindings_changed(self, screen: Screen[Any]) -> None:
        if self._built_from is not None and screen is self.screen and _bindings(screen) == self._built_from:
            return
        super().bindings_changed(screen)


def _bindings(screen: Screen[Any]) -> list[Any]:
    """What the footer's keys are made from: every active binding, whether it is enabled, its tooltip."""
    return [(binding, enabled, tooltip) for _, binding, enabled, tooltip in screen.active_bindings.values()]
