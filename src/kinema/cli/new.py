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
    # Without a terminal there is nobody to answer the template's questions: use their defaults.
    no_input = no_input or not click.get_text_stream("stdin").isatty()
    overlaid = found.package(name) if found.has_package(name) else None
    path = new_config_package(name, based_on, output_dir, workspace=found, no_input=no_input)
    click.echo(f"created config package {name} in {path}")
    if overlaid is not None and overlaid.origin == "bundled":
        click.echo(f"note: it overlays Kinema's bundled {name} ({overlaid.path}) in this workspace")
    # Where the package went may be outside what commands find from here (``-o`` elsewhere): the
    # hint must be a command that works.
    refound, _ = resolve_selection(workspace, None, need_config=False)
    if refound.has_package(name):
        click.echo(f"try: kinema config show -c {name} --provenance")
    elif path.parent.name == "src":
        click.echo(f"try: kinema config show -c {name} -w {path.parent.parent} --provenance")
    else:
        click.echo(
            f"note: {path.parent} is not a workspace's src/ folder, so kinema commands do not find {name} "
            "from here; create it inside a workspace (kinema init WS, then kinema new config ... -w WS)"
        )


@new.command("behavior")
@click.argument("name")
@click.option(
    "-t",
    "--type",
    "behavior_type",
    type=click.Choice(
        ["sync", "async", "service_client", "action_client", "topic_subscriber", "topic_publisher"]
    ),
    default="async",
    show_default=True,
    help="The base class: sync (one tick), async (work off the tick thread), service_client (AddTwoInts), "
    "action_client (Fibonacci), topic_subscriber / topic_publisher (std_msgs/String).",
)
@click.option(
    "-p",
    "--package",
    default=None,
    metavar="PKG",
    help="Add the behavior to this existing behavior package of the workspace instead of creating one.",
)
@workspace_option
@click.option(
    "-c",
    "--config",
    default=None,
    metavar="NAME",
    help="Config package to register the new loader in (default: the active one, if it is in the workspace).",
)
def new_behavior(
    name: str, behavior_type: str, package: str | None, workspace: Path | None, config: str | None
) -> None:
    """Create behavior NAME (snake_case; its ID is the CamelCase form) in the workspace's src/.

    Without --package, a behavior package named NAME is created: pyproject.toml with its loader entry
    point, the behavior module, the registration, an example objective and a passing test. The example
    works before any edit (e.g. async sums int_1 and int_2; service_client calls /add_two_ints). When the
    active config package is in the workspace, the loader and the example objectives are added to its
    config.yaml. Nothing is written when a name is invalid or taken, or when it would shadow a Python
    module (a standard-library or installed one, e.g. os or numpy).
    """
    from kinema.cli.options import resolve_selection
    from kinema.scaffold.behavior_package import new_behavior as create

    found, active = resolve_selection(workspace, config, need_config=False)
    result = create(name, behavior_type, workspace=found, package=package, config=active or None)
    if result.created_package:
        click.echo(f"created behavior package {result.package} in {result.package_dir}")
    else:
        click.echo(f"added behavior {result.behavior_id} to {result.package} ({result.package_dir})")
    for path in result.files:
        click.echo(f"  {path.relative_to(result.package_dir)}")
    click.echo(f"behavior {result.behavior_id} ({behavior_type}), loader {result.loader_name}")
    if result.config_file is not None and result.config_changes:
        click.echo(f"updated {result.config_file}:")
        for change in result.config_changes:
            click.echo(f"  {change}")
    elif result.config_file is None:
        click.echo(
            "to use it, add the loader to your config package's objectives.behavior_loader_plugins "
            f'(e.g. {result.package}: ["{result.loader_name}"])'
        )
    click.echo(f"test it: kinema test --packages-select {result.package}")
