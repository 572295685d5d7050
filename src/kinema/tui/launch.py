"""The TUI as ``kinema run``'s user interface: it owns the runtime the launcher started.

``kinema run`` (without ``--headless``) passes :func:`run_for_launcher` as the launcher's ``ui``. The app
joins the router the launcher hosts, like any client. Closing the app stops the runtime (the launcher
stops its children when the UI returns); ``kinema down`` or a crashed child closes the app.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING

from kinema.tui.app import KinemaApp
from kinema.tui.sdk_connection import SdkConnection

if TYPE_CHECKING:
    from kinema.runtime.launcher import Launcher


def run_for_launcher(launcher: Launcher) -> int:
    """Run the app until the user closes it or the launcher is told to stop; return the exit code."""
    options = launcher.options
    connection = SdkConnection(launcher.endpoint, workspace=options.workspace, config=options.config)
    app = KinemaApp(connection, owns_runtime=True)
    outcome = {"code": 0}
    app_closed = threading.Event()

    def watch_launcher() -> None:
        code = launcher.wait()  # returns on `kinema down`, a signal, a dead child, or our request below
        if app_closed.is_set():
            return
        outcome["code"] = code
        try:
            app.call_from_thread(app.exit)
        except RuntimeError:
            pass  # the app was already closing

    watcher = threading.Thread(target=watch_launcher, name="kinema-ui-launcher-watch", daemon=True)
    watcher.start()
    try:
        app.run()
    finally:
        app_closed.set()
        launcher.request_stop("the terminal UI was closed")
        watcher.join(timeout=2.0)
    return outcome["code"]
