"""``kinema security init``: certificates and access rules, so that the cell opens to a LAN securely."""

from __future__ import annotations

from pathlib import Path

import click

from kinema.cli.groups import VerbGroup


@click.group(cls=VerbGroup, invoke_without_command=True)
@click.option(
    "-d",
    "--dir",
    "folder",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    help="The security folder whose clients to list (default: $KINEMA_SECURITY_DIR, else "
    "~/.config/kinema/security).",
)
@click.pass_context
def security(ctx: click.Context, folder: Path | None) -> None:
    """Open a cell to other machines securely: certificates, access rules, zenoh configs.

    Without a verb: print the roles (what an operator may do, what needs the XML grant) and which clients
    of the security folder hold which.
    """
    if ctx.invoked_subcommand is None:
        _print_roles(folder)


@security.command("roles")
@click.option(
    "-d",
    "--dir",
    "folder",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    help="The security folder whose clients to list (default: $KINEMA_SECURITY_DIR, else "
    "~/.config/kinema/security).",
)
def roles(folder: Path | None) -> None:
    """Print the roles and which clients hold them (what `kinema security` prints)."""
    _print_roles(folder)


def _print_roles(folder: Path | None) -> None:
    import textwrap

    from kinema.transport.security_folder import default_security_dir, describe_roles, holders

    for line in describe_roles():
        indent = len(line) - len(line.lstrip(" -"))
        click.echo(textwrap.fill(line, 100, subsequent_indent=" " * indent))
    path = folder or default_security_dir()
    held = holders(path)
    click.echo("")
    if held is None:
        click.echo(f"no security folder at {path} yet: `kinema security init` makes one")
        return
    click.echo(f"clients of {path}:")
    for name, role in held:
        click.echo(f"  {name}: {role}")


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
    "--allow-xml",
    "xml_clients",
    multiple=True,
    metavar="NAME",
    help="A --client that may also run ad-hoc objective XML (/do_objective, `kinema objective do`); "
    "operators run the library's objectives by name otherwise (repeatable).",
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
    xml_clients: tuple[str, ...],
    folder: Path | None,
    port: int,
    local: str,
    force: bool,
) -> None:
    """Make a certificate authority, the router's certificate, client configs and access rules.

    Afterwards `kinema run --connect tls/<ADDRESS>:7448` listens for other machines with mutual TLS
    (each side shows a certificate signed by this CA) and the access rules: processes on this machine
    may do everything; an operator's machine may run the library's objectives by name (with parameters),
    cancel and watch them, read waypoints and watch the robot's state, and with --allow-xml run ad-hoc
    objective XML; no objective reads or writes files outside the workspace, the config packages and
    Kinema's data folder, or anything in this folder (`kinema security` prints the roles); another
    machine of the cell (--machine) may do everything. Copy clients/<NAME>.json5 (one file) to that
    machine and use it there with KINEMA_ZENOH_CONFIG=<NAME>.json5 (`kinema ui`, `kinema objective ...`,
    or `kinema run -n --connect tls/<ADDRESS>:7448` on a machine).
    Running it again keeps the CA (and the clients it signed) unless --force.
    """
    from kinema.transport import resolve_domain_id
    from kinema.transport.exposure import is_loopback
    from kinema.transport.security_folder import (
        default_security_dir,
        holders,
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
        xml_clients=list(xml_clients),
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
    for name, role in holders(result.path) or []:
        click.echo(f"  {name}: {role}")
    click.echo("`kinema security` lists what each role may do")
    click.echo("")
    click.echo(f"on this machine:  kinema run --connect {result.tls_endpoints[0]}")
    click.echo(
        f"on an operator's: copy {result.clients[0].name} there, then "
        f"KINEMA_ZENOH_CONFIG={result.clients[0].name} kinema ui"
    )
    _say_running_routers_keep_their_rules()


def _say_running_routers_keep_their_rules() -> None:
    """A router reads its access rules once, at start: a client added now is refused until it restarts
    (its client saw only "no runtime answered")."""
    from kinema.runtime.instance import running_instances

    for record in running_instances():
        click.secho(
            f"note: the running kinema run (pid {record.pid}, config {record.config or '-'}) read the access "
            "rules when it started: restart it (`kinema down`, then `kinema run --connect ...`) for these "
            "certificates and rules to take effect",
            err=True,
            fg="yellow",
        )
