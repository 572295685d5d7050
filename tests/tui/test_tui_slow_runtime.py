"""With a slow runtime the app answers at once and every key lands where it was typed.

Every call to the scripted runtime takes two seconds here (a loaded machine); the app makes them off the UI
thread, and keys typed while a screen comes up wait for it instead of going to the screen being left.
"""

from __future__ import annotations

from textual import events
from textual.widgets import Input
from tui_pilot_harness import drive, settle

from kinema.tui.fake_connection import FakeConnection
from kinema.tui.screens.blackboard import BlackboardScreen
from kinema.tui.screens.objectives import ObjectivesScreen


def type_fast(app, keys: str | list[str]) -> None:  # type: ignore[no-untyped-def]
    """Keys in one burst, as a terminal delivers what was typed while the app was busy (the Pilot's
    ``press`` waits for each key to be handled, which hides exactly the race this file is about)."""
    names = {"/": "slash", " ": "space"}
    for key in keys:
        name = names.get(key, key)
        character = key if len(key) == 1 else None
        app.post_message(events.Key(name, character))


def test_typing_and_switching_screens_while_every_call_is_slow() -> None:
    fake = FakeConnection.demo()
    fake.delay = 2.0

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        # F5 lists the objectives again (two seconds): meanwhile the search box takes letters at once.
        await pilot.press("f5")
        type_fast(app, "grip")
        await pilot.pause(0.3)
        listing = [w for w in app.workers if w.name == "List objectives" and not w.is_finished]
        assert listing, "the slow call should still run, off the UI thread"
        assert app.screen.query_one("#objective-search", Input).value == "grip"
        # "3" switches screens; "/" and the letters typed right after belong to the Blackboard screen.
        await pilot.press("escape", "tab")
        type_fast(app, ["3", "/", *"count"])
        await pilot.pause(0.5)
        await settle(pilot)
        assert isinstance(app.screen, BlackboardScreen)
        assert app.screen.query_one("#blackboard-filter", Input).value == "count"
        objectives = next(view for view in app.views if isinstance(view, ObjectivesScreen))
        assert objectives.query_one("#objective-search", Input).value == "grip"  # nothing strayed back
        assert fake.called("start_objective") == []

    drive(fake, scenario)
