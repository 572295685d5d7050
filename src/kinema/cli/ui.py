"""``kinema ui``: open the terminal UI attached to a runtime that is already running."""

from __future__ import annotations

from pathlib import Path

import click

from kinema.cli.options import selection_options

SCREEN_CHOICES = ("configs", "objectives", "blackboard", "behaviors", "logs", "waypoints")


@click.command()
@click.option(
    "--connect",
    "endpoint",
    default=None,
    metavar="ENDPOINT",
    help="Zenoh endpoint of the runtime, e.g. tcp/192.168.1.20:7447 "
    "(default: $KINEMA_ZENOH_CONNECT, else tcp/127.0.0.1:7447).",
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
@selection_options
def ui(endpoint: str | None, screen: str, demo: bool, workspace: Path | None, config: str | None) -> None:
    """Open the terminal UI attached to a running runtime (`kinema run` in another terminal or machine).

    Closing the UI leaves the runtime running. The Configs screen browses the workspace selected with
    -w/-c (or `kinema configure`). Keys: 1-6 switch screens, ctrl+p opens the command palette, q quits.
    """
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
    run_app(connection, owns_runtime=False, initial_mode=screen)
