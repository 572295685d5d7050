"""Driving the app headless with the Pilot: the app that records notifications, settle(), drive()."""

from __future__ import annotations

import asyncio
from collections.abc import Awaitable, Callable

from textual.pilot import Pilot

from kinema.tui.app import KinemaApp
from kinema.tui.fake_connection import FakeConnection

SIZE = (140, 40)
Scenario = Callable[["RecordingApp", Pilot[None]], Awaitable[None]]


async def settle(pilot: Pilot[None]) -> None:
    """Let posted messages, workers started by them, and the messages they post back all finish."""
    for _ in range(3):
        await pilot.pause()
        await pilot.app.workers.wait_for_complete()
    await pilot.pause()


class RecordingApp(KinemaApp):
    """The app, remembering every notification it showed (``title: message``) for assertions."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        self.shown: list[str] = []

    def notify(self, message: str, *, title: str = "", **kwargs: object) -> None:  # type: ignore[override]
        self.shown.append(f"{title}: {message}" if title else message)
        super().notify(message, title=title, **kwargs)  # type: ignore[arg-type]


def drive(
    connection: FakeConnection,
    scenario: Scenario,
    *,
    mode: str = "objectives",
    size: tuple[int, int] = SIZE,
    **app_args: object,
) -> None:
    """Run ``scenario`` against a headless app on ``connection``, opened on screen ``mode``."""
    app = RecordingApp(connection, initial_mode=mode, **app_args)

    async def main() -> None:
        async with app.run_test(size=size) as pilot:
            await settle(pilot)
            await scenario(app, pilot)

    asyncio.run(main())
