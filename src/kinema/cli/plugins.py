"""``kinema plugins`` and ``kinema behaviors``: what the active config's behavior loaders provide."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from kinema.cli.options import selection_options


def _load(workspace: Path | None, config: str | None) -> tuple[Any, Any, str]:
    from kinema.cli.options import resolve_selection
    from kinema.config import resolve_config
    from kinema.plugins import BehaviorHost

    found, name = resolve_selection(workspace, config)
    resolved = resolve_config(name, found, check_files=False)
    host = BehaviorHost.for_config(resolved)
    report = host.load()
    return host, report, resolved.name


def _print_problems(report: Any) -> None:
    from kinema.cli.options import print_warnings

    print_warnings(report.warnings)
    for error in report.errors:
        click.secho(f"error: {error}", err=True, fg="red")


@click.command()
@selection_options
@click.option("--json", "as_json", is_flag=True, help="Print JSON (one object per plugin) instead of text.")
def plugins(workspace: Path | None, config: str | None, as_json: bool) -> None:
    """List the behavior plugins the active config loads: where each comes from and what it registered.

    The config's objectives.behavior_loader_plugins (unioned across its based_on_package chain) selects
    the plugins among the bundled ones, installed entry points (kinema.behaviors) and the behavior
    packages of the workspace. Exits 1 when a plugin failed to load.
    """
    import json

    host, report, name = _load(workspace, config)
    records = host.plugins
    if as_json:
        click.echo(
            json.dumps(
                [
                    {
                        "name": record.name,
                        "source": str(record.spec.source),
                        "package": record.spec.package,
                        "where": record.spec.where,
                        "behaviors": list(record.behaviors),
                        "error": str(record.error) if record.error is not None else None,
                    }
                    for record in records
                ],
                indent=2,
            )
        )
    else:
        click.echo(f"Behavior plugins of config {name}:")
        for record in records:
            state = (
                click.style("failed", fg="red")
                if record.error is not None
                else f"{len(record.behaviors)} behaviors"
            )
            click.echo(f"  {click.style(record.name, bold=True)}  [{record.spec.source}] {state}")
            click.echo(f"      from {record.spec.where}")
            if record.behaviors:
                click.echo(f"      {', '.join(record.behaviors)}")
            if record.error is not None:
                click.secho(f"      {record.error}", fg="red")
    _print_problems(report)
    if not report.ok:
        raise click.exceptions.Exit(1)


@click.command()
@selection_options
@click.option(
    "--json", "as_json", is_flag=True, help="Print JSON: each behavior with its ports and metadata."
)
@click.option(
    "--markdown",
    is_flag=True,
    help="Print the behavior reference as Markdown (by subcategory; ports with direction, type, default).",
)
@click.argument("behavior_ids", nargs=-1, metavar="[ID]...")
def behaviors(
    workspace: Path | None,
    config: str | None,
    as_json: bool,
    markdown: bool,
    behavior_ids: tuple[str, ...],
) -> None:
    """List the behaviors the active config can use (or only the IDs given), with their ports and metadata.

    With --markdown, print them as a behavior reference (docs/behavior-reference.md is this for lab_sim).
    """
    import json

    from kinema.errors import PluginError, did_you_mean

    host, report, _name = _load(workspace, config)
    registry = host.registry
    for behavior_id in behavior_ids:
        if behavior_id not in registry:
            raise PluginError(
                f"no behavior '{behavior_id}' in the active config; {did_you_mean(behavior_id, registry)}"
            )
    chosen = [registry[i] for i in (behavior_ids or sorted(registry))]
    if as_json:
        click.echo(json.dumps([_behavior_json(record) for record in chosen], indent=2))
    elif markdown:
        from kinema.plugins.reference import reference_markdown

        click.echo(reference_markdown(chosen), nl=False)
    else:
        for record in chosen:
            _print_behavior(record)
    _print_problems(report)


def _port_json(port: Any) -> dict[str, Any]:
    return {
        "name": port.name,
        "direction": port.direction.xml_tag.replace("_port", ""),
        "type": port.type_name,
        "default": port.default_str,
        "description": port.description,
    }


def _behavior_json(record: Any) -> dict[str, Any]:
    return {
        "id": record.behavior_id,
        "plugin": record.plugin,
        "class": record.cls.__name__,
        "location": str(record.location),
        "metadata": dict(record.metadata),
        "ports": [_port_json(port) for port in record.ports],
    }


def _print_behavior(record: Any) -> None:
    subcategory = record.metadata.get("subcategory", "")
    click.echo(f"{click.style(record.behavior_id, bold=True)}  ({subcategory}; plugin {record.plugin})")
    description = record.metadata.get("description", "")
    if description:
        click.echo(f"    {description}")
    for port in record.ports:
        default = f" = {port.default_str}" if port.default_str is not None else ""
        text = f" — {port.description}" if port.description else ""
        direction = port.direction.xml_tag.replace("_port", "")
        click.echo(f"    {direction:<5} {port.name}: {port.type_name}{default}{text}")
