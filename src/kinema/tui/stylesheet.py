"""The app's stylesheet: Textual's, parsing each CSS source once while the CSS variables stay the same.

Textual parses a source (``app.tcss``, each widget class's ``DEFAULT_CSS``) into rules and keeps them in a
cache keyed by the source. Two things threw that cache away on the way to the first frame: setting the
variables clears it, even to the same values, and a reparse parses every source in a new stylesheet whose
cache is dropped afterwards. The app refreshes its CSS (both at once) when it first shows a screen, so every
source read by then was parsed three times: ``app.tcss`` alone took 4-5 ms each time.

Here setting the variables to the values they have changes nothing, and a reparse parses in place, through
the cache. The rules are the same: a source's rules depend only on its text and the variables.
"""

from __future__ import annotations

from textual.css.stylesheet import Stylesheet

__all__ = ["OnceParsedStylesheet"]


class OnceParsedStylesheet(Stylesheet):
    """Textual's :class:`~textual.css.stylesheet.Stylesheet`, keeping its parsed sources while the
    variables stay the same (see the module's docstring)."""

    def set_variables(self, variables: dict[str, str]) -> None:
        if variables != self._variables:
            super().set_variables(variables)

    def reparse(self) -> None:
        # Textual parses into a new stylesheet so that an error leaves this one as it was; parse() does
        # too (it sets the rules only once all parsed). Invalid sources are tried again, as there.
        self._invalid_css.clear()
        self.parse()
