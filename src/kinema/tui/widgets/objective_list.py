"""The objective list: letters typed on it search, Enter runs the highlighted objective, a click only selects.

Running an objective moves the robot, so it is never a printable key and never a click: a user typing a
name into what looks like the search box must not start one. Every printable key on the list but the
digits goes to the search box, ahead of the screen's and the app's keys (``q`` included); the digits stay
the app's screen keys, as the tabs above every screen say (in the search box they are typed).
"""

from __future__ import annotations

from textual import events
from textual.binding import Binding
from textual.widgets import Input, OptionList


class ObjectiveSearch(Input):
    """The search box above an :class:`ObjectiveList`: Enter and Down hand the keys to the list.

    At once (``set_focus``, not the ``Submitted`` message's later handler): a second Enter typed right
    after the first is resolved against the focus of that moment, and must run the objective.

    Args:
        objectives: the id of the list.
    """

    def __init__(self, *, objectives: str, placeholder: str, id: str | None = None) -> None:
        super().__init__(placeholder=placeholder, id=id, select_on_focus=False)
        self.objectives = objectives

    def _to_list(self) -> None:
        self.screen.set_focus(self.screen.query_one(f"#{self.objectives}", OptionList))

    async def action_submit(self) -> None:
        self._to_list()
        await super().action_submit()

    async def _on_key(self, event: events.Key) -> None:
        if event.key == "down":
            event.stop()
            event.prevent_default()
            self._to_list()


class ObjectiveList(OptionList):
    """An :class:`OptionList` of objectives (option ids are the objective names).

    Args:
        search: the id of the search box (an :class:`Input` on the same screen) typed letters go to.
    """

    BINDINGS = [
        Binding("enter", "select", "Run", id="objectives.run_selected", tooltip="Run the selected objective"),
    ]

    def __init__(self, *, search: str, id: str | None = None) -> None:
        super().__init__(id=id)
        self.search = search

    # Textual calls the handler of every class in the MRO until one prevents the default: these run first
    # and keep OptionList's from acting on a printable key or a click.
    async def _on_key(self, event: events.Key) -> None:
        if event.is_printable and event.character and not event.character.isdigit():
            event.stop()
            event.prevent_default()
            search = self.screen.query_one(f"#{self.search}", Input)
            # At once, not with focus() (a later call): the keys typed right after this one are already
            # on their way, and the app resolves their bindings against whatever has the focus then.
            self.screen.set_focus(search)
            if event.character != "/":  # the search key itself
                search.insert_text_at_cursor(event.character)

    async def _on_click(self, event: events.Click) -> None:
        # Highlighting shows the objective; running it is Enter's (or ctrl+r's) job.
        event.prevent_default()
        clicked: int | None = event.style.meta.get("option")
        if clicked is not None and not self.get_option_at_index(clicked).disabled:
            self.highlighted = clicked
