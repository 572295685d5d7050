"""The footer shows the keys of what has the focus, and keeps its key widgets while those stay the same."""

from __future__ import annotations

from textual.widgets import Input
from textual.widgets._footer import FooterKey
from tui_pilot_harness import RecordingApp, drive, settle

from kinema.tui.fake_connection import FakeConnection


def footer_keys(app: RecordingApp) -> list[FooterKey]:
    return list(app.screen.query(FooterKey))


def shown(app: RecordingApp) -> list[str]:
    return [key.description for key in footer_keys(app)]


def test_the_footer_follows_the_focus(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        assert shown(app)[:2] == ["Run", "Search"]
        await pilot.press("slash")  # the search box: Enter types there, it runs nothing
        await settle(pilot)
        assert isinstance(app.focused, Input)
        assert "Run" not in shown(app) and "Search" in shown(app)
        app.screen.set_focus(app.screen.query_one("#objective-list"))  # back to the list
        await settle(pilot)
        assert shown(app)[:2] == ["Run", "Search"]

    drive(fake, scenario)


def test_the_footer_keeps_its_keys_when_the_bindings_stay_the_same(fake: FakeConnection) -> None:
    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        before = footer_keys(app)
        assert before
        app.screen.refresh_bindings()  # what every widget mounted with bindings does
        await settle(pilot)
        assert footer_keys(app) == before  # the same widgets: not removed and mounted again

    drive(fake, scenario)
