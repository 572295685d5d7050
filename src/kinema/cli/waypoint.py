"""``kinema waypoint …``: list, save, rename and erase the running config's waypoints.

Each verb calls the agent's waypoint services (``/get_waypoints``, ``/edit_waypoints``) through the SDK, as
the terminal UI's Waypoints tab does; the agent writes the waypoints file (atomically). A waypoint is moved
to with ``kinema objective run "Move to Waypoint" -p waypoint_name=NAME``.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import click

from kinema.cli.groups import VerbGroup
from kinema.cli.options import refuse_other_config, selection_options

if TYPE_CHECKING:
    from kinema.config import Waypoint
    from kinema.sdk import ObjectiveClient

_CONNECT_HELP = (
    "Router endpoint to join (default: $KINEMA_ZENOH_CONNECT, else the endpoint of $KINEMA_ZENOH_CONFIG, "
    "else tcp/127.0.0.1:7447)."
)

connect_option = click.option("--connect", "-e", metavar="ENDPOINT", default=None, help=_CONNECT_HELP)
timeout_option = click.option(
    "--timeout", type=float, default=5.0, show_default=True, help="Seconds to wait for the runtime."
)


@contextmanager
def _client(connect: str | None, timeout: float) -> Iterator[ObjectiveClient]:
    from kinema.sdk import ObjectiveClient

    with ObjectiveClient(connect, timeout=timeout) as client:
        yield client


def _positions(waypoint: Waypoint) -> str:
    return ", ".join(
        f"{name}={value:.4g}" for name, value in zip(waypoint.joint_names, waypoint.positions, strict=True)
    )


@click.group(cls=VerbGroup)
def waypoint() -> None:
    """List, save, rename and erase the running config's waypoints (as the UI's Waypoints tab does)."""


@waypoint.command("list")
@click.option("--json", "as_json", is_flag=True, help="Print [{name, groups, joints: {name: position}}].")
@selection_options
@connect_option
@timeout_option
def list_(
    as_json: bool, workspace: Path | None, config: str | None, connect: str | None, timeout: float
) -> None:
    """List the saved waypoints (* marks favorites) with their planning groups; --json adds the joints.

    They come from the running runtime; with none running, from the waypoints file of the selected config
    (-w/-c, else the one `kinema configure` set), which the runtime would serve."""
    import json

    from kinema.errors import TransportError

    try:
        with _client(connect, timeout) as client:
            _check_running_config(client, config)
            found = client.waypoints()
    except TransportError:
        found = _from_file(workspace, config)
    if as_json:
        rows = [{"name": w.name, "groups": w.joint_group_names, "joints": w.joint_positions()} for w in found]
        click.echo(json.dumps(rows, indent=2))
        return
    if not found:
        click.echo("no waypoints saved (`kinema waypoint save NAME` saves where the robot is)")
        return
    width = max(len(w.name) for w in found)
    for item in found:
        groups = ", ".join(item.joint_group_names) or "-"
        click.echo(f"{'*' if item.favorite else ' '} {item.name:<{width}}  {groups}")


def _check_running_config(client: ObjectiveClient, config: str | None) -> None:
    """With ``-c NAME`` and a runtime running: it must serve that config, as ``kinema objective run -c``
    checks."""
    if not config:
        return
    from kinema.transport.presence import AGENT, query_presences

    running = [m.config for m in query_presences(client.session) if m.role == AGENT and m.config]
    refuse_other_config(running, config, "its waypoints are that config's")


def _from_file(workspace: Path | None, config: str | None) -> list[Waypoint]:
    """The selected config's waypoints as its file holds them (no runtime answered), said on stderr."""
    from kinema.cli.options import resolve_selection
    from kinema.config import resolve_config
    from kinema.config.waypoint_location import waypoint_store_for

    found, name = resolve_selection(workspace, config)
    store = waypoint_store_for(resolve_config(name, found))
    if store is None:
        raise click.ClickException(f"no runtime answered, and config {name!r} names no waypoints file")
    click.secho(f"note: no runtime answered; the waypoints of config {name} in {store.read_path}", err=True)
    return store.all()


@waypoint.command("save")
@click.argument("name")
@click.option(
    "--group",
    "-g",
    "groups",
    multiple=True,
    metavar="GROUP",
    help="Planning group the waypoint is for; repeatable (default: the config's planning group).",
)
@connect_option
@timeout_option
def save(name: str, groups: tuple[str, ...], connect: str | None, timeout: float) -> None:
    """Save where the robot is now as waypoint NAME (replacing a waypoint of that name)."""
    with _client(connect, timeout) as client:
        existed = any(w.name == name for w in client.waypoints())
        saved = client.save_waypoint(name, groups)
    verb = "replaced" if existed else "saved"
    click.echo(
        f"{verb} waypoint {saved.name!r} ({', '.join(saved.joint_group_names) or 'no group'}): "
        f"{_positions(saved)}"
    )


@waypoint.command("rename")
@click.argument("name")
@click.argument("new_name")
@connect_option
@timeout_option
def rename(name: str, new_name: str, connect: str | None, timeout: float) -> None:
    """Rename waypoint NAME to NEW_NAME."""
    with _client(connect, timeout) as client:
        renamed = client.rename_waypoint(name, new_name)
    click.echo(f"renamed waypoint {name!r} to {renamed.name!r}")


@waypoint.command("erase")
@click.argument("name")
@connect_option
@timeout_option
def erase(name: str, connect: str | None, timeout: float) -> None:
    """Delete waypoint NAME (its joint values are printed, so it can be typed back in)."""
    with _client(connect, timeout) as client:
        gone = next((w for w in client.waypoints() if w.name == name), None)
        client.erase_waypoint(name)
    was = f": it was {_positions(gone)}" if gone is not None else ""
    click.echo(f"erased waypoint {name!r}{was}")
