"""``kinema new``: generate packages from Kinema's templates."""

from __future__ import annotations

from pathlib import Path

import click

from kinema.cli.options import workspace_option


@click.group()
def new() -> None:
    """Generate a new package from a template."""


@new.command("config")
@click.argument("name", required=False)
@click.option("-n", "--package-name", default=None, help="Name of the new package (same as NAME).")
@click.option("-b", "--based-on", default=None, metavar="PARENT", help="Config package to inherit from.")
@click.option(
    "-o",
    "--output-dir",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    help="Where to create the package (default: the active workspace's src/).",
)
@workspace_option
@click.option("--no-input", is_flag=True, help="Do not ask anything; use defaults for what is not given.")
def new_config(
    name: str | None,
    package_name: str | None,
    based_on: str | None,
    output_dir: Path | None,
    workspace: Path | None,
    no_input: bool,
) -> None:
    """Create config package NAME based on PARENT.

    The package gets config/config.yaml with based_on_package, its own objectives/ folder registered
    under objective_library_paths, and package.xml. Nothing is written when the name is invalid or
    taken, the parent is unknown or the folder exists.
    """
    from kinema.cli.options import resolve_selection
    from kinema.errors import ScaffoldError
    from kinema.scaffold import new_config_package

    if name and package_name and name != package_name:
        raise ScaffoldError(
            f"NAME ({name!r}) and --package-name ({package_name!r}) disagree; give one of them"
        )
    name = name or package_name
    found, active = resolve_selection(workspace, None, need_config=False)
    if name is None:
        if no_input:
            raise ScaffoldError("the package name is missing: kinema new config NAME --based-on PARENT")
        name = click.prompt("Package name")
    if based_on is None:
        if no_input:
            raise ScaffoldError(
                "--based-on PARENT is missing (`kinema config list` shows the config packages)"
            )
        choices = [package.name for package in found.config_packages(include_hidden=True)]
        click.echo("Config packages: " + ", ".join(choices))
        based_on = click.prompt(
            "Based on", default=active if active in choices else (choices[0] if choices else None)
        )
    assert name is not None and based_on is not None
    path = new_config_package(name, based_on, output_dir, workspace=found, no_input=no_input)
    click.echo(f"created config package {name} in {path}")
    click.echo(f"try: kinema config show -c {name} --provenance")
