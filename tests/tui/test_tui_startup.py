"""The way to the first frame: the first screen is composed and styled once, the collector held meanwhile."""

from __future__ import annotations

import asyncio
import gc
from collections.abc import Iterator
from typing import Any

import pytest
import textual.css.parse as parse_module
import textual.css.stylesheet as stylesheet_module
import textual.screen
from textual import events
from textual.dom import DOMNode
from textual.geometry import Size
from textual.screen import Screen
from textual.widgets._footer import FooterKey

from kinema.tui import startup_gc
from kinema.tui.app import KinemaApp
from kinema.tui.fake_connection import FakeConnection
from kinema.tui.screens.base import breakpoint_classes


class RestyleRecordingApp(KinemaApp):
    """The app, remembering each node Textual restyled with all its descendants."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        self.restyled: list[DOMNode] = []

    def update_styles(self, node: DOMNode, animate: bool = True) -> None:
        self.restyled.append(node)
        super().update_styles(node, animate)


@pytest.fixture
def collector() -> Iterator[None]:
    """Leave the garbage collector as the test found it (on, nothing frozen)."""
    yield
    startup_gc.release()
    gc.unfreeze()
    gc.enable()


@pytest.mark.parametrize("size", [(80, 24), (120, 40)])
@pytest.mark.parametrize("mode", ["objectives", "blackboard"])
def test_the_first_screen_is_not_restyled_as_a_whole_before_it_is_used(
    fake: FakeConnection, mode: str, size: tuple[int, int]
) -> None:
    # Textual restyles a screen and every widget in it when the screen resumes and when its size classes
    # change; neither has anything new to apply to a screen composed a moment ago.
    app = RestyleRecordingApp(fake, initial_mode=mode)

    async def main() -> None:
        async with app.run_test(size=size) as pilot:
            await pilot.pause()
            await pilot.pause()
            assert app.current_mode == mode
            assert app.screen_stack == [app.screen]
            assert set(breakpoint_classes(app)) <= app.screen.classes
            assert [node for node in app.restyled if isinstance(node, Screen)] == []

    asyncio.run(main())


def test_a_screen_shown_again_is_restyled(fake: FakeConnection) -> None:
    """The first resume skips the restyle, later ones do not (the styles may have changed meanwhile)."""
    app = RestyleRecordingApp(fake, initial_mode="objectives")

    async def main() -> None:
        async with app.run_test(size=(120, 40)) as pilot:
            await pilot.pause()
            objectives = app.screen
            await app.action_switch_mode("logs")
            await pilot.pause()
            app.restyled.clear()
            await app.action_switch_mode("objectives")
            await pilot.pause()
            assert objectives in app.restyled

    asyncio.run(main())


@pytest.mark.parametrize(
    ("size", "classes"),
    [
        ((80, 24), ["-narrow", "-short"]),
        ((99, 31), ["-narrow", "-short"]),
        ((100, 32), ["-normal", "-tall"]),
        ((200, 60), ["-normal", "-tall"]),
    ],
)
def test_breakpoint_classes_are_textuals(
    fake: FakeConnection, size: tuple[int, int], classes: list[str]
) -> None:
    app = KinemaApp(fake, initial_mode="logs")

    async def main() -> None:
        async with app.run_test(size=size) as pilot:
            await pilot.pause()
            assert breakpoint_classes(app) == classes
            # The classes Textual itself gave the screen at this size.
            given = app.screen.classes & {"-narrow", "-normal", "-short", "-tall"}
            assert given == set(classes)

    asyncio.run(main())


def test_an_unknown_first_screen_is_an_error_naming_the_screens(fake: FakeConnection) -> None:
    with pytest.raises(ValueError, match=r"no screen 'object'.*objectives.*waypoints"):
        KinemaApp(fake, initial_mode="object")


def test_held_collector_resumes_after_the_first_frame_with_the_start_up_frozen(
    fake: FakeConnection, collector: None
) -> None:
    startup_gc.hold()
    assert not gc.isenabled()
    app = KinemaApp(fake)

    async def main() -> None:
        async with app.run_test(size=(120, 40)) as pilot:
            await pilot.pause()
            await pilot.pause()
            assert gc.isenabled()
            assert gc.get_freeze_count() > 10_000  # Textual's and the screen's objects

    asyncio.run(main())


def test_a_collector_turned_off_by_someone_else_stays_off(collector: None) -> None:
    gc.disable()
    startup_gc.hold()
    startup_gc.settle()
    assert not gc.isenabled()
    startup_gc.release()
    assert not gc.isenabled()


def test_the_footers_keys_are_styled_once_and_only_the_palette_key_is_compact(fake: FakeConnection) -> None:
    # Textual's footer keys start compact and are made wide by the footer right after they mount: two
    # restyles of each on the way to the first frame. They start as the footer is.
    app = RestyleRecordingApp(fake, initial_mode="objectives")

    async def main() -> None:
        async with app.run_test(size=(120, 40)) as pilot:
            await pilot.pause()
            await pilot.pause()
            keys = list(app.screen.query(FooterKey))
            assert len(keys) > 3
            palette = [key for key in keys if key.has_class("-command-palette")]
            assert [key for key in keys if key.has_class("-compact")] == palette
            assert all(not key.compact for key in keys if key not in palette)
            assert [node for node in app.restyled if isinstance(node, FooterKey)] == palette

    asyncio.run(main())


def test_a_resize_to_the_size_the_screen_has_lays_nothing_out_again(
    fake: FakeConnection, monkeypatch: pytest.MonkeyPatch
) -> None:
    laid_out: list[Size] = []
    original = Screen._on_resize

    async def recording(self: Screen[object], event: events.Resize) -> None:
        laid_out.append(event.size)
        await original(self, event)

    monkeypatch.setattr(Screen, "_on_resize", recording)
    app = KinemaApp(fake, initial_mode="objectives")

    async def main() -> None:
        async with app.run_test(size=(120, 40)) as pilot:
            await pilot.pause()
            app.screen.post_message(events.Resize(Size(120, 40), Size(120, 40)))
            await pilot.pause()
            assert laid_out == []  # the start's resizes too (each laid the screen out again)
            await pilot.resize_terminal(90, 30)
            await pilot.pause(0.1)
            assert laid_out == [Size(90, 30)]
            assert app.screen.query_one("#status-bar").region.bottom == 29  # laid out at the new size
            assert {"-narrow", "-short"} <= app.screen.classes

    asyncio.run(main())


def test_the_first_frame_is_drawn_once_the_start_is_over_not_on_a_tick_of_the_update_timer(
    fake: FakeConnection, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Textual draws on the ticks of each screen's update timer (60 Hz); with ticks 10 s apart, only a
    # frame drawn as soon as the start is over arrives in time.
    monkeypatch.setattr(textual.screen, "UPDATE_PERIOD", 10.0)
    drawn: list[Screen[object]] = []
    original = KinemaApp._display

    def recording(self: KinemaApp, screen: Screen[object], renderable: Any) -> None:
        if not self._batch_count:  # within the start's batch update the app draws nothing
            drawn.append(screen)
        original(self, screen, renderable)

    monkeypatch.setattr(KinemaApp, "_display", recording)
    app = KinemaApp(fake, initial_mode="objectives")

    async def main() -> None:
        async with app.run_test(size=(120, 40)):
            for _ in range(40):  # not the pilot's pause, which makes the screen draw itself
                if drawn:
                    break
                await asyncio.sleep(0.05)
            assert drawn and drawn[-1] is app.screen

    asyncio.run(main())


def test_the_apps_stylesheet_is_parsed_once_and_again_for_a_new_theme(
    fake: FakeConnection, monkeypatch: pytest.MonkeyPatch
) -> None:
    parsed: list[str] = []
    original = parse_module.parse

    def recording(scope: str, css: str, read_from: tuple[str, str], *args: Any, **kwargs: Any) -> Any:
        parsed.append(read_from[0])
        return original(scope, css, read_from, *args, **kwargs)

    monkeypatch.setattr(stylesheet_module, "parse", recording)
    app = KinemaApp(fake, initial_mode="objectives")

    def app_tcss() -> int:
        return sum(path.endswith("app.tcss") for path in parsed)

    async def main() -> None:
        async with app.run_test(size=(120, 40)) as pilot:
            await pilot.pause()
            assert app_tcss() == 1  # Textual's refresh when it first showed the screen parsed it twice more
            dark = app.screen.styles.background
            app.theme = "textual-light"
            await pilot.pause()
            assert app_tcss() == 2 and app.screen.styles.background != dark

    asyncio.run(main())
