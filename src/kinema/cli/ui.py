"""``kinema ui``: open the terminal UI attached to a runtime that is already running."""

from __future__ import annotations

import threading
from pathlib import Path

import click

from kinema.cli.options import selection_options

SCREEN_CHOICES = ("configs", "objectives", "blackboard", "behaviors", "logs", "waypoints")


@click.command()
@click.option(
    "--connect",
    "-e",
    "endpoint",
    default=None,
    metavar="ENDPOINT",
    help="Zenoh endpoint of the runtime, e.g. tcp/192.168.1.20:7447 "
    "(default: $KINEMA_ZENOH_CONNECT, else the endpoint of $KINEMA_ZENOH_CONFIG, else tcp/127.0.0.1:7447).",
)
@click.option(
    "-s",
    "--screen",
    type=click.Choice(SCREEN_CHOICES),
    default="objectives",
    show_default=True,
    help="The screen to open first.",
)
@click.option(
    "--demo",
    is_flag=True,
    help="Show the app on a built-in demo runtime (no runtime needed; for a first look).",
)
@click.option(
    "--replay",
    "replay",
    is_flag=False,
    flag_value="latest",
    default=None,
    metavar="[FILE.btlog]",
    help="Replay a recorded run instead (no runtime needed): step through its transitions and see the "
    "blackboard at each. Without FILE, the newest recording (see `kinema logs --recordings`).",
)
@click.option(
    "--camera",
    "camera",
    default=None,
    metavar="TOPIC",
    help="Also open the camera view on this image topic, e.g. /wrist_camera/color (key 7 opens it too).",
)
@selection_options
def ui(
    endpoint: str | None,
    screen: str,
    demo: bool,
    replay: str | None,
    camera: str | None,
    workspace: Path | None,
    config: str | None,
) -> None:
    """Open the terminal UI attached to a running runtime (`kinema run` in another terminal or machine).

    Closing the UI leaves the runtime running. The Configs screen browses the workspace selected with
    -w/-c (or `kinema configure`). Keys: 1-6 switch screens, 7 shows a camera image, ctrl+p opens the
    command palette, ctrl+x cancels the running objective, ctrl+q quits (on the objective list, letters
    and q search; Esc leaves the search box).
    """
    if replay is not None:
        _replay(replay)
        return
    from kinema.tui import startup_gc

    startup_gc.hold()  # until the first frame (see startup_gc)
    # With --camera the first screen draws images: ask the terminal what it can draw while the app's
    # modules load. The questions wait for answers (up to 0.1 s each in a terminal that gives none) and
    # must be asked before the app owns the terminal. Without --camera the app asks when the camera view
    # first opens. Rich (which both sides import, and Textual needs first anyway) is loaded before, so
    # the two threads do not import the same modules at once.
    probe: threading.Thread | None = None
    if camera:
        import rich.console  # noqa: F401

        probe = threading.Thread(target=_probe_image_support, name="kinema-ui-image-probe", daemon=True)
        probe.start()
    from kinema.tui.app import run_app
    from kinema.tui.connection import RuntimeConnection

    connection: RuntimeConnection
    if demo:
        from kinema.tui.fake_connection import FakeConnection

        fake = FakeConnection.demo()
        if workspace is not None:
            fake.workspace_root = str(workspace)
        connection = fake
    else:
        from kinema.tui.sdk_connection import SdkConnection

        connection = SdkConnection(endpoint=endpoint, workspace=workspace, config=config)
    if probe is not None:
        probe.join()
    run_app(connection, owns_runtime=False, initial_mode=screen, camera=camera)


def _probe_image_support() -> None:
    from kinema.tui.screens.camera import load_image_support

    load_image_support()


def _replay(which: str) -> None:
    from kinema.bt.btlog import read_btlog
    from kinema.runtime.recordings import latest_recording
    from kinema.tui.screens.replay import ReplayApp

    path = latest_recording() if which == "latest" else Path(which)
    read_btlog(path)  # a missing or foreign file is a one-line error here, not inside the app
    ReplayApp(path).run()
