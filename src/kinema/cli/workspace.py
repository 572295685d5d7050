"""``kinema configure`` and ``kinema init``: choosing and creating workspaces."""

from __future__ import annotations

import os
from pathlib import Path

import click

from kinema.errors import ConfigError


@click.command()
@click.option(
    "-w",
    "--workspace",
    default=None,
    metavar="PATH",
    help="Workspace folder (one with src/); empty means none (bundled configs only). Asked for when "
    "missing, unless -c is given (then the current workspace is kept).",
)
@click.option(
    "-c", "--config", default=None, metavar="NAME", help="Config package to use. Asked for when missing."
)
def configure(workspace: str | None, config: str | None) -> None:
    """Set the active workspace and config package for later commands.

    The choice is stored in the user's config folder (~/.config/kinema/selection.yaml on Linux);
    KINEMA_WORKSPACE and KINEMA_CONFIG override it, and every verb's -w/-c override both.
    """
    from kinema.config import Workspace, active_selection, store_selection
    from kinema.config.selection import CONFIG_ENV, WORKSPACE_ENV
    from kinema.config.workspace import find_workspace_root
    from kinema.errors import did_you_mean

    current = active_selection()
    if workspace is None and config is not None:
        # `kinema configure -c NAME` switches the config package and keeps the workspace.
        workspace = str(current.workspace) if current.workspace else ""
    elif workspace is None:
        workspace = click.prompt(
            "Workspace folder (empty: none, bundled configs only)",
            default=str(current.workspace) if current.workspace else "",
            show_default=bool(current.workspace),
        )
    root = find_workspace_root(Path(workspace)) if workspace.strip() else None
    found = Workspace.discover(root) if root is not None else Workspace.bundled_only()
    names = [package.name for package in found.config_packages()]
    if config is None:
        if not names:
            raise ConfigError(f"there are no config packages in {found.describe()}")
        default = current.config if current.config in names else names[0]
        click.echo("Config packages: " + ", ".join(names))
        config = click.prompt("Config package", default=default, type=click.Choice(names), show_choices=False)
    all_names = [package.name for package in found.config_packages(include_hidden=True)]
    if not found.has_package(config) or not found.package(config).is_config:
        raise ConfigError(
            f"no config package named {config!r} in {found.describe()}; {did_you_mean(config, all_names)}"
        )
    path = store_selection(root, found.package(config).name)
    click.echo(f"workspace: {root if root is not None else '(none, bundled configs only)'}")
    click.echo(f"config:    {found.package(config).name}")
    click.echo(f"stored in {path}")
    for variable in (WORKSPACE_ENV, CONFIG_ENV):
        if os.environ.get(variable):
            click.secho(f"note: {variable} is set and overrides this choice", err=True, fg="yellow")


@click.command()
@click.argument("path", type=click.Path(file_okay=False, path_type=Path))
def init(path: Path) -> None:
    """Create an empty workspace at PATH (a folder with src/ for your packages).

    Then add a config package for your own robot with `kinema new config NAME -w PATH --from-urdf URDF`
    (docs/own-robot.md), or start from Kinema's bundled simulated lab: `kinema configure -w PATH -c
    lab_sim`, then `kinema new config NAME --based-on lab_sim`.
    """
    path = path.expanduser()
    if path.exists() and not path.is_dir():
        raise ConfigError(f"{path} exists and is not a folder")
    src = path / "src"
    if src.is_dir():
        raise ConfigError(f"{path} is already a workspace (it has src/)")
    readme = path / "README.md"
    try:
        src.mkdir(parents=True)
        if not readme.exists():
            readme.write_text(
                "# Kinema workspace\n\n"
                "Packages live in `src/`: config packages (`config/config.yaml`) and behavior packages.\n\n"
                "Your own robot, from its URDF (a path or a `package://` URI; the SRDF is optional):\n\n"
                "```bash\n"
                "kinema new config my_robot_config -w . --from-urdf path/to/robot.urdf "
                "--srdf path/to/robot.srdf\n"
                "kinema build -c my_robot_config -w .\n"
                "kinema run -c my_robot_config -w .\n"
                "```\n\n"
                "Or start from Kinema's bundled simulated lab and change what differs:\n\n"
                "```bash\n"
                "kinema configure -w . -c lab_sim\n"
                "kinema new config my_cell --based-on lab_sim\n"
                "kinema config show -c my_cell --provenance\n"
                "```\n",
                encoding="utf-8",
            )
    except OSError as error:
        raise ConfigError(f"cannot create the workspace {path}: {error.strerror or error}") from None
    click.echo(f"created workspace {path.resolve()}")
    click.echo(f"next, your own robot:   kinema new config NAME -w {path} --from-urdf URDF [--srdf SRDF]")
    click.echo(f"  or the bundled lab:   kinema configure -w {path} -c lab_sim")
