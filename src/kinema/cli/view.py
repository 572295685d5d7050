"""``kinema view``: a running runtime's 3D scene in the browser (the counterpart of ``moveit_pro rviz``)."""

from __future__ import annotations

from pathlib import Path

import click

from kinema.cli.options import selection_options


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
@click.option("--no-browser", is_flag=True, help="Only print the URL; do not open a browser.")
@click.option(
    "--port",
    type=click.IntRange(1, 65535),
    default=None,
    help="HTTP port on 127.0.0.1 (default: the first free one from 7000 up).",
)
@click.option(
    "--rate",
    type=click.FloatRange(1.0, 240.0),
    default=60.0,
    show_default=True,
    help="Most scene updates per second sent to the page.",
)
@selection_options
def view(
    endpoint: str | None,
    no_browser: bool,
    port: int | None,
    rate: float,
    workspace: Path | None,
    config: str | None,
) -> None:
    """Show the running robot, objects, planned paths and markers in the browser (meshcat).

    Attaches to the runtime started with `kinema run` (here or at --connect), serves the 3D view on
    127.0.0.1 only and prints its URL; works offline. The scene is the MuJoCo model of the runtime's
    config (-c to name another). Runs until Ctrl-C; the page says so when the runtime goes away and
    follows it again when it comes back: a runtime started again with another config has that
    config's scene drawn (unless -c named one).
    """
    from kinema.viz.view import ViewerOptions, run_viewer

    options = ViewerOptions(
        endpoint=endpoint,
        config=config,
        workspace=workspace,
        port=port,
        open_browser=not no_browser,
        frame_rate=rate,
        echo=click.echo,
    )
    code = run_viewer(options)
    if code:
        raise click.exceptions.Exit(code)
