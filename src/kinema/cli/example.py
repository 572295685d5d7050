"""``kinema example``: small demo servers used by the tutorials."""

from __future__ import annotations

import click

from kinema.cli.groups import VerbGroup


@click.group(cls=VerbGroup)
def example() -> None:
    """Demo programs from the tutorials (each runs until Ctrl-C)."""


@example.command("add-two-ints-server")
@click.option("--name", default="/add_two_ints", show_default=True, help="Service name to serve.")
@click.option(
    "--connect",
    "-e",
    default=None,
    metavar="ENDPOINT",
    help="Router to join (default: $KINEMA_ZENOH_CONNECT, else the endpoint of $KINEMA_ZENOH_CONFIG, else "
    "tcp/127.0.0.1:7447).",
)
def add_two_ints_server(name: str, connect: str | None) -> None:
    """Serve example_interfaces/srv/AddTwoInts (the tutorial's external service); print each request."""
    from kinema.process.stop import TERMINATE, StopRequest
    from kinema.transport import Node, open_session

    def add(request):  # type: ignore[no-untyped-def]
        total = int(request.a) + int(request.b)
        click.echo(f"request: a={request.a} b={request.b} -> sum={total}")
        return {"sum": total}

    with StopRequest().handle_signals(TERMINATE) as stop, open_session(connect) as session:
        node = Node(session, "add_two_ints_server")
        node.create_service("example_interfaces/srv/AddTwoInts", name, add)
        click.echo(f"serving {name} [example_interfaces/srv/AddTwoInts]; Ctrl-C stops")
        stop.wait()
