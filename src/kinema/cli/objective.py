"""``kinema objective``: the objectives of a config (``list``, ``show``; running comes with the runtime)."""

from __future__ import annotations

import json
from pathlib import Path

import click

from kinema.cli.options import print_notices, resolve_selection, selection_options, verbose_option


@click.group()
def objective() -> None:
    """List, inspect and run the objectives of a config package."""


def _load_library(workspace: Path | None, config: str | None, verbose: bool):  # type: ignore[no-untyped-def]
    from kinema.config import ObjectiveLibrary, resolve_config

    found, name = resolve_selection(workspace, config)
    resolved = resolve_config(name, found)
    library = ObjectiveLibrary.load(resolved)
    if verbose:
        print_notices([*resolved.notices, *library.notices])
    return library


@objective.command("list")
@selection_options
@click.option(
    "--json", "as_json", is_flag=True, help='Print {"config", "objectives": [...], "errors": [...]}.'
)
@verbose_option
def list_(workspace: Path | None, config: str | None, as_json: bool, verbose: bool) -> None:
    """List the objectives of the config's objective libraries.

    Columns: R = runnable (subtree-only objectives are not), * = favorite. Files that cannot be read are
    reported as file:line: message on stderr; the other objectives are still listed.
    """
    library = _load_library(workspace, config, verbose)
    objectives = library.sorted()
    if as_json:
        payload = {
            "config": library.resolved.name if library.resolved else None,
            "objectives": [info.to_json() for info in objectives],
            "errors": [str(error) for error in library.errors],
        }
        click.echo(json.dumps(payload, indent=2))
        return
    for error in library.errors:
        click.secho(f"warning: {error}", err=True, fg="yellow")
    if not objectives:
        click.echo("no objectives")
        return
    width = max(len(info.id) for info in objectives)
    category_width = max(len(info.subcategory or "-") for info in objectives)
    for info in objectives:
        flags = ("R" if info.runnable else "-") + ("*" if info.favorite else " ")
        click.echo(f"{flags} {info.id:<{width}}  {info.subcategory or '-':<{category_width}}  {info.package}")


@objective.command()
@click.argument("name")
@selection_options
@click.option("--xml", "as_xml", is_flag=True, help="Print only the XML file of the objective.")
@click.option("--json", "as_json", is_flag=True, help="Print the objective's metadata and ports as JSON.")
@verbose_option
def show(
    name: str, workspace: Path | None, config: str | None, as_xml: bool, as_json: bool, verbose: bool
) -> None:
    """Show one objective: source file, metadata, ports and XML."""
    library = _load_library(workspace, config, verbose)
    info = library.get(name)
    if as_xml:
        click.echo(info.read_xml(), nl=False)
        return
    if as_json:
        click.echo(json.dumps({**info.to_json(), "xml": info.read_xml()}, indent=2))
        return
    click.echo(f"{info.id}")
    click.echo(f"  file:        {info.location}")
    click.echo(f"  package:     {info.package}")
    click.echo(f"  description: {info.description or '-'}")
    click.echo(f"  subcategory: {info.subcategory or '-'}")
    click.echo(f"  runnable:    {'yes' if info.runnable else 'no (subtree only)'}")
    click.echo(f"  favorite:    {'yes' if info.favorite else 'no'}")
    for path in info.shadows:
        click.echo(f"  shadows:     {path}")
    if info.ports:
        click.echo("  ports:")
        width = max(len(port.name) for port in info.ports)
        for port in info.ports:
            default = f" = {port.default}" if port.default is not None else ""
            description = f"  ({port.description})" if port.description else ""
            click.echo(f"    {port.direction:<6} {port.name:<{width}}{default}{description}")
    else:
        click.echo("  ports:       none")
    click.echo("")
    click.echo(info.read_xml(), nl=False)
