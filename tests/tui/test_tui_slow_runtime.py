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


async def wait_until(pilot, predicate, what: str, timeout: float = 5.0) -> None:  # type: ignore[no-untyped-def]
    """Let the app run until ``predicate()`` holds (keys in a burst are handled one per message)."""
    from textual.css.query import NoMatches

    for _ in range(int(timeout / 0.05)):
        try:
            if predicate():
                return
        except NoMatches:
            pass  # the screen is still being composed
        await pilot.pause(0.05)
    raise AssertionError(f"not within {timeout} s: {what}")


def test_typing_and_switching_screens_while_every_call_is_slow() -> None:
    fake = FakeConnection.demo()
    # Slow enough that the listing still runs after the keys are handled on a loaded machine.
    fake.delay = 6.0

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        # F5 lists the objectives again (two seconds): meanwhile the search box takes letters at once.
        await pilot.press("f5")
        type_fast(app, "grip")
        search = app.screen.query_one("#objective-search", Input)
        await wait_until(
            pilot, lambda: search.value == "grip", f"'grip' in the search box (it has {search.value!r})"
        )
        listing = [w for w in app.workers if w.name == "List objectives" and not w.is_finished]
        assert listing, "the slow call should still run, off the UI thread"
        # "3" switches screens; "/" and the letters typed right after belong to the Blackboard screen.
        await pilot.press("escape", "tab")
        type_fast(app, ["3", "/", *"count"])
        await wait_until(pilot, lambda: isinstance(app.screen, BlackboardScreen), "the Blackboard screen")
        await wait_until(
            pilot,
            lambda: app.screen.query_one("#blackboard-filter", Input).value == "count",
            "'count' in the blackboard filter",
        )
        await settle(pilot)
        assert isinstance(app.screen, BlackboardScreen)
        assert app.screen.query_one("#blackboard-filter", Input).value == "count"
        objectives = next(view for view in app.views if isinstance(view, ObjectivesScreen))
        assert objectives.query_one("#objective-search", Input).value == "grip"  # nothing strayed back
        assert fake.called("start_objective") == []

    drive(fake, scenario)
