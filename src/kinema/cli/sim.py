"""``kinema sim …``: look at and reset the running MuJoCo simulation.

Every verb joins the router at ``--connect`` and calls the driver's ``/mujoco/*`` services; it exits 1
with one line when no simulation answers within ``--timeout``.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

import click

from kinema.cli.groups import VerbGroup
from kinema.errors import DriverError

if TYPE_CHECKING:
    from kinema.drivers.mujoco.client import SimClient

_CONNECT_HELP = (
    "Router endpoint to join (default: $KINEMA_ZENOH_CONNECT, else the endpoint of $KINEMA_ZENOH_CONFIG, "
    "else tcp/127.0.0.1:7447)."
)


def _common(func: Callable[..., Any]) -> Callable[..., Any]:
    func = click.option("--connect", "-e", "connect", metavar="ENDPOINT", default=None, help=_CONNECT_HELP)(
        func
    )
    return click.option(
        "--timeout", type=float, default=5.0, show_default=True, help="Seconds to wait for the simulation."
    )(func)


@contextmanager
def _client(connect: str | None, timeout: float) -> Iterator[SimClient]:
    from kinema.drivers.mujoco.client import SimClient
    from kinema.transport import Node, open_session

    with open_session(connect, connect_timeout=min(max(timeout, 0.5), 5.0)) as session:
        yield SimClient(Node(session, f"_kinema_sim_cli_{os.getpid()}"), timeout)


@click.group(cls=VerbGroup)
def sim() -> None:
    """Inspect and reset the running MuJoCo simulation (free bodies, joints, keyframes)."""


@sim.command("bodies")
@click.option(
    "--json", "as_json", is_flag=True, help="Print {sim_time, bodies: [{name, position, orientation}]}."
)
@_common
def bodies(as_json: bool, connect: str | None, timeout: float) -> None:
    """Print each free body's name and world position (m), from the running simulator."""
    import json

    with _client(connect, timeout) as client:
        sim_time, found = client.bodies()
    if as_json:
        click.echo(json.dumps({"sim_time": sim_time, "bodies": [b.to_json() for b in found]}, indent=2))
        return
    if not found:
        click.echo(f"no free bodies (sim time {sim_time:.3f} s)")
        return
    width = max(len(b.name) for b in found)
    click.echo(f"{'body':<{width}}  {'x':>8} {'y':>8} {'z':>8}    (sim time {sim_time:.3f} s)")
    for body in found:
        x, y, z = body.position
        click.echo(f"{body.name:<{width}}  {x:8.4f} {y:8.4f} {z:8.4f}")


@sim.command("joints")
@click.option("--json", "as_json", is_flag=True, help="Print {joints: {name: position}, velocities: {...}}.")
@_common
def joints(as_json: bool, connect: str | None, timeout: float) -> None:
    """Print each joint's position (rad or m) and velocity, from the next /joint_states message."""
    import json

    from kinema.drivers.mujoco.names import JOINT_STATES_TOPIC, JOINT_STATES_TYPE
    from kinema.sdk.streams import MessageStream
    from kinema.transport import Node, open_session

    with open_session(connect, connect_timeout=min(max(timeout, 0.5), 5.0)) as session:
        node = Node(session, f"_kinema_sim_cli_{os.getpid()}")
        with MessageStream(
            lambda callback: node.create_subscription(JOINT_STATES_TYPE, JOINT_STATES_TOPIC, callback),
            lambda message: message,
            timeout=timeout,
        ) as stream:
            message = next(iter(stream), None)
    if message is None:
        raise DriverError(
            f"no {JOINT_STATES_TOPIC} message within {timeout:g} s: is a simulation running "
            "(`kinema run`)? (--timeout waits longer)"
        )
    names = list(message.name)
    positions = [float(v) for v in message.position]
    velocities = [float(v) for v in message.velocity] if len(message.velocity) == len(names) else []
    if as_json:
        click.echo(
            json.dumps(
                {
                    "joints": dict(zip(names, positions, strict=True)),
                    "velocities": dict(zip(names, velocities, strict=False)),
                },
                indent=2,
            )
        )
        return
    width = max((len(name) for name in names), default=5)
    click.echo(f"{'joint':<{width}}  {'position':>10}  {'velocity':>10}")
    for index, name in enumerate(names):
        velocity = f"{velocities[index]:10.4f}" if velocities else f"{'-':>10}"
        click.echo(f"{name:<{width}}  {positions[index]:10.4f}  {velocity}")


@sim.command("keyframes")
@click.option("--json", "as_json", is_flag=True, help="Print {keyframes: [...], initial}.")
@_common
def keyframes(as_json: bool, connect: str | None, timeout: float) -> None:
    """List the simulation's keyframes (the one it started from is marked with *)."""
    import json

    with _client(connect, timeout) as client:
        found, initial = client.keyframes()
    if as_json:
        click.echo(json.dumps({"keyframes": found, "initial": initial}))
        return
    for name in found:
        click.echo(f"{'*' if name == initial else ' '} {name}")


@sim.command("reset")
@click.argument("keyframe", required=False)
@_common
def reset(keyframe: str | None, connect: str | None, timeout: float) -> None:
    """Reset robot and objects to KEYFRAME (default: the keyframe the simulation started from)."""
    with _client(connect, timeout) as client:
        if not keyframe:
            found, keyframe = client.keyframes()
            if not keyframe:
                raise DriverError(
                    "the simulation did not start from a keyframe; name one: " + (", ".join(found) or "none")
                )
        click.echo(client.set_state(keyframe=keyframe))


@sim.command("set-joints")
@click.argument("assignments", nargs=-1, required=True, metavar="JOINT=VALUE...")
@_common
def set_joints(assignments: tuple[str, ...], connect: str | None, timeout: float) -> None:
    """Teleport joints to positions given as JOINT=VALUE (m or rad).

    Example: `kinema sim set-joints elbow_joint=1.2 wrist_1_joint=-1.5`. The controllers hold the
    joints where they are set; a trajectory in progress is aborted.
    """
    positions: dict[str, float] = {}
    for item in assignments:
        name, sep, value = item.partition("=")
        try:
            if not sep or not name:
                raise ValueError
            positions[name.strip()] = float(value)
        except ValueError:
            raise click.BadParameter(f"{item!r} is not JOINT=VALUE (e.g. elbow_joint=1.2)") from None
    with _client(connect, timeout) as client:
        click.echo(client.set_state(positions=positions))
