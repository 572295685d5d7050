"""``kinema config``: list config packages, show a merged config with provenance, print a chain."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from kinema.cli.groups import VerbGroup
from kinema.cli.options import (
    print_notices,
    print_warnings,
    resolve_selection,
    selection_options,
    verbose_option,
    workspace_option,
)


@click.group(cls=VerbGroup)
def config() -> None:
    """Inspect robot config packages and their inheritance."""


@config.command("list")
@workspace_option
@click.option(
    "-a", "--all", "include_hidden", is_flag=True, help="Also list packages hidden by KINEMA_IGNORE."
)
@click.option("--json", "as_json", is_flag=True, help="Print a JSON list.")
@verbose_option
def list_(workspace: Path | None, include_hidden: bool, as_json: bool, verbose: bool) -> None:
    """List the config packages of the workspace (and the bundled ones).

    The active config is marked with *. Packages with a KINEMA_IGNORE or MOVEIT_PRO_IGNORE file are
    hidden unless --all is given.
    """
    import json

    from kinema.config import list_config_packages
    from kinema.config.inheritance import load_config_source
    from kinema.errors import ConfigError

    found, active = resolve_selection(workspace, None, need_config=False)
    if verbose:
        print_notices(found.notices)
    rows: list[dict[str, Any]] = []
    for package in list_config_packages(found, include_hidden=include_hidden):
        try:
            based_on = load_config_source(package).based_on or ""
            problem = ""
        except ConfigError as error:
            based_on, problem = "", str(error)
        rows.append(
            {
                "name": package.name,
                "based_on": based_on,
                "origin": package.origin,
                "path": str(package.path),
                "hidden": package.hidden,
                "active": package.name == active,
                "error": problem or None,
            }
        )
    if as_json:
        click.echo(json.dumps(rows, indent=2))
        return
    if not rows:
        click.echo(f"no config packages in {found.describe()}")
        return
    width = max(len(row["name"]) for row in rows)
    based_width = max(len("based on"), *(len(row["based_on"]) for row in rows))
    for row in rows:
        mark = "*" if row["active"] else " "
        extra = " (hidden)" if row["hidden"] else ""
        based_on = row["based_on"] or "-"
        name = f"{row['name']:<{width}}"
        click.echo(f"{mark} {name}  {based_on:<{based_width}}  {row['origin']:<9}  {row['path']}{extra}")
        if row["error"]:
            click.secho(f"    error: {row['error']}", fg="red")


@config.command()
@selection_options
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object shaped like config.yaml.")
@click.option("-p", "--provenance", is_flag=True, help="Show which package set each value.")
@click.option("--no-check", is_flag=True, help="Do not check that the referenced files exist.")
@verbose_option
def show(
    workspace: Path | None, config: str | None, as_json: bool, provenance: bool, no_check: bool, verbose: bool
) -> None:
    """Print the merged config of a package and its whole inheritance chain.

    Without --json it is readable YAML; --provenance adds, for each value, the package that set it
    (as a comment, or in JSON as {"config", "chain", "provenance"} with dotted key paths).
    """
    import json

    from kinema.config import resolve_config

    found, name = resolve_selection(workspace, config)
    resolved = resolve_config(name, found, check_files=not no_check)
    print_warnings(resolved.warnings)
    if verbose:
        print_notices(resolved.notices)
    if as_json:
        click.echo(json.dumps(resolved.to_json(provenance=provenance), indent=2, default=str))
        return
    click.echo(f"# config {resolved.name} (chain: {' → '.join(resolved.chain)})")
    click.echo(render_yaml(resolved.data, resolved.provenance if provenance else None), nl=False)


@config.command()
@selection_options
@click.option("--json", "as_json", is_flag=True, help="Print a JSON list, root first.")
def chain(workspace: Path | None, config: str | None, as_json: bool) -> None:
    """Print the inheritance chain of a config package, root first."""
    import json

    from kinema.config.inheritance import resolve_chain

    found, name = resolve_selection(workspace, config)
    sources = resolve_chain(name, found)
    if as_json:
        click.echo(
            json.dumps([{"name": s.package.name, "path": str(s.package.path)} for s in sources], indent=2)
        )
        return
    width = max(len(source.package.name) for source in sources)
    for source in sources:
        click.echo(f"{source.package.name:<{width}}  {source.document.path}")


def render_yaml(data: dict[str, Any], provenance: dict[str, str] | None) -> str:
    """Render merged config data as block YAML; with ``provenance``, each value ends with ``# package``."""
    import yaml

    if provenance is None:
        return yaml.safe_dump(data, sort_keys=False, allow_unicode=True, default_flow_style=False, width=100)
    lines: list[str] = []
    _emit(data, "", 0, provenance, lines)
    return "\n".join(lines) + "\n"


def _flow(value: Any) -> str:
    import yaml

    text = yaml.safe_dump(value, default_flow_style=True, allow_unicode=True, width=10_000)
    return text.strip().removesuffix("...").strip()


def _emit(
    value: dict[Any, Any], path: str, indent: int, provenance: dict[str, str], lines: list[str]
) -> None:
    from kinema.config.refs import is_ref

    pad = "  " * indent
    for key, item in value.items():
        key_text = _flow(key)
        child = f"{path}.{key}" if path else str(key)
        if isinstance(item, dict) and item and not is_ref(item):
            lines.append(f"{pad}{key_text}:")
            _emit(item, child, indent + 1, provenance, lines)
        elif isinstance(item, list) and item and f"{child}[0]" in provenance:
            lines.append(f"{pad}{key_text}:")
            for index, element in enumerate(item):
                lines.append(f"{pad}  - {_flow(element)}  # {provenance.get(f'{child}[{index}]', '?')}")
        else:
            lines.append(f"{pad}{key_text}: {_flow(item)}  # {provenance.get(child, '?')}")
