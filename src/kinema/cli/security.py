"""``kinema security init``: certificates and access rules, so that the cell opens to a LAN securely."""

from __future__ import annotations

from pathlib import Path

import click


@click.group()
def security() -> None:
    """Open a cell to other machines securely: certificates, access rules, zenoh configs."""


@security.command("init")
@click.option(
    "-a",
    "--address",
    "addresses",
    multiple=True,
    metavar="ADDRESS",
    help="An IP address or host name other machines reach this one at (repeatable; default: this "
    "machine's addresses).",
)
@click.option(
    "--client",
    "clients",
    multiple=True,
    metavar="NAME",
    help="An operator machine to make a client config for (repeatable; default: operator).",
)
@click.option(
    "--machine",
    "machines",
    multiple=True,
    metavar="NAME",
    help="Another machine of this cell (one running `kinema run -n` or `-o`): a client config with full "
    "access (repeatable).",
)
@click.option(
    "-d",
    "--dir",
    "folder",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    help="Where to write (default: $KINEMA_SECURITY_DIR, else ~/.config/kinema/security).",
)
@click.option("--port", type=click.IntRange(1, 65535), default=7448, show_default=True, help="The TLS port.")
@click.option(
    "--local",
    default="tcp/127.0.0.1:7447",
    show_default=True,
    metavar="ENDPOINT",
    help="The loopback endpoint this machine's own processes use (in router.json5).",
)
@click.option("--force", is_flag=True, help="Make a new certificate authority (invalidates issued clients).")
def init(
    addresses: tuple[str, ...],
    clients: tuple[str, ...],
    machines: tuple[str, ...],
    folder: Path | None,
    port: int,
    local: str,
    force: bool,
) -> None:
    """Make a certificate authority, the router's certificate, client configs and access rules.

    Afterwards `kinema run --connect tls/<ADDRESS>:7448` listens for other machines with mutual TLS
    (each side shows a certificate signed by this CA) and the access rules: processes on this machine
    may do everything; an operator's machine may start, cancel and watch objectives, read waypoints and
    watch the robot's state; another machine of the cell (--machine) may do everything. Copy
    clients/<NAME>.json5 (one file) to that machine and use it there with KINEMA_ZENOH_CONFIG=<NAME>.json5
    (`kinema ui`, `kinema objective ...`, or `kinema run -n --connect tls/<ADDRESS>:7448` on a machine).
    Running it again keeps the CA (and the clients it signed) unless --force.
    """
    from kinema.transport import resolve_domain_id
    from kinema.transport.exposure import is_loopback
    from kinema.transport.security_folder import (
        default_security_dir,
        init_security_folder,
        this_machines_addresses,
    )

    if not is_loopback(local):
        raise click.BadParameter(f"{local} is not a loopback endpoint", param_hint="--local")
    chosen = list(addresses) or this_machines_addresses()
    if not chosen:
        raise click.UsageError("found no address of this machine that others could reach: pass --address")
    result = init_security_folder(
        folder or default_security_dir(),
        addresses=chosen,
        clients=list(clients) or ([] if machines else ["operator"]),
        machines=list(machines),
        port=port,
        local_endpoint=local,
        domain_id=resolve_domain_id(None),
        force=force,
    )
    ca = "kept the certificate authority" if result.reused_ca else "made a certificate authority"
    click.echo(
        f"{ca} and the router's certificate in {result.path} (addresses: {', '.join(result.addresses)})"
    )
    for client in result.clients:
        click.echo(f"client config: {client}")
    click.echo(f"router config: {result.router_config}")
    click.echo("")
    click.echo(f"on this machine:  kinema run --connect {result.tls_endpoints[0]}")
    click.echo(
        f"on an operator's: copy {result.clients[0].name} there, then "
        f"KINEMA_ZENOH_CONFIG={result.clients[0].name} kinema ui"
    )
