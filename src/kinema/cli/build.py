"""``kinema build`` and ``kinema test``: prepare and check a workspace's behavior packages."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from kinema.cli.options import selection_options
from kinema.errors import KinemaError


def _model_path(workspace_root: Path | None, config: str) -> Path:
    if workspace_root is not None:
        return workspace_root / "build" / "kinema" / config / "tree_nodes_model.xml"
    import platformdirs

    return Path(platformdirs.user_cache_dir("kinema")) / config / "tree_nodes_model.xml"


@click.command()
@click.argument(
    "target", type=click.Choice(["all", "user_workspace"]), default="user_workspace", required=False
)
@click.option(
    "--packages-select",
    multiple=True,
    metavar="PKG",
    help="Only these behavior packages (repeat the option for several).",
)
@click.option("--skip-install", is_flag=True, help="Do not install dependencies; only validate and export.")
@selection_options
def build(
    target: str,
    packages_select: tuple[str, ...],
    skip_install: bool,
    workspace: Path | None,
    config: str | None,
) -> None:
    """Install dependencies, validate the objectives and export the TreeNodesModel for Groot2.

    \b
    1. pip-installs what each behavior package of the workspace declares in [project] dependencies
       (already satisfied requirements are skipped, so it is fast and offline when nothing changed);
    2. loads the active config's behavior plugins and validates every objective of its objective
       library against them (unknown behaviors, ports, types, missing subtrees), printing file:line;
    3. writes the TreeNodesModel XML of the config's behaviors and prints its path;
    4. checks the robot: every name that crosses its files (URDF, SRDF, joint limits, MuJoCo scene,
       waypoints, controllers, tool frame, sensor) and every file they name, printing file:line.

    TARGET is accepted for MoveIt Pro habits: `all` and `user_workspace` do the same here (there is no
    image to build; behavior packages are loaded from their folders). Exits 1 on any error.
    """
    from kinema.cli.options import print_warnings, resolve_selection
    from kinema.config import resolve_config
    from kinema.config.robot_check import robot_report
    from kinema.plugins import BehaviorHost
    from kinema.plugins.dependencies import pip_install, unsatisfied, workspace_behavior_packages
    from kinema.plugins.validation import validate_objectives, write_tree_nodes_model

    found, name = resolve_selection(workspace, config)
    errors = 0
    packages = workspace_behavior_packages(found.root, packages_select) if found.root is not None else []
    if packages_select and found.root is None:
        raise click.UsageError("--packages-select needs a workspace (-w PATH)")
    if not skip_install:
        for index, package in enumerate(packages, start=1):
            prefix = f"[{index}/{len(packages)}] {package.name}:"
            missing = unsatisfied(package.dependencies)
            if not missing:
                click.echo(f"{prefix} dependencies satisfied ({len(package.dependencies)})")
                continue
            click.echo(f"{prefix} installing {', '.join(missing)}")
            pip_install(missing, lambda line: click.echo(f"    {line}"))

    resolved = resolve_config(name, found)
    print_warnings(resolved.warnings)
    waypoint_error = _read_waypoints(resolved)
    host = BehaviorHost.for_config(resolved)
    report = host.load()
    print_warnings(report.warnings)
    for error in report.errors:
        click.secho(str(error), err=True, fg="red")
        errors += 1
    registry = host.registry
    click.echo(f"{len(registry)} behaviors from {len(host.plugins)} plugins for config {resolved.name}")

    file_count, problems, warnings = validate_objectives(resolved, registry)
    print_warnings(warnings)
    for problem in problems:
        click.secho(str(problem), err=True, fg="red")
    errors += len(problems)
    click.echo(f"validated {_count(file_count, 'objective file')}: {_count(len(problems), 'problem')}")

    model = write_tree_nodes_model(registry, _model_path(found.root, resolved.name))
    click.echo(f"TreeNodesModel for Groot2: {model}")

    robot = robot_report(resolved)
    print_warnings(robot.warnings)
    said = {str(robot_problem) for robot_problem in robot.problems}
    if waypoint_error is not None and str(waypoint_error) not in said:
        click.secho(str(waypoint_error), err=True, fg="red")  # the robot check did not say it
        errors += 1
    for robot_problem in robot.problems:
        click.secho(str(robot_problem), err=True, fg="red")
    errors += len(robot.problems)
    click.echo(f"checked the robot: {_count(len(robot.problems), 'problem')}")
    if errors:
        click.secho(f"build failed: {_count(errors, 'error')}", err=True, fg="red")
        raise click.exceptions.Exit(1)


def _read_waypoints(resolved: object) -> KinemaError | None:
    """Read the config's waypoints as the runtime will; the error when they do not load (the robot check
    names each bad waypoint too: the caller prints this one only when it did not)."""
    from kinema.config.waypoint_location import waypoint_store_for

    try:
        store = waypoint_store_for(resolved)  # type: ignore[arg-type]
        if store is None:
            return None
        count = len(store.all())
    except KinemaError as error:
        return error
    click.echo(f"read {count} waypoints from {store.read_path}")
    return None


@click.command()
@click.option(
    "--packages-select",
    multiple=True,
    metavar="PKG",
    help="Only these behavior packages (repeat the option for several).",
)
@click.option(
    "-w",
    "--workspace",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    help="Workspace folder (default: $KINEMA_WORKSPACE, else the one set with `kinema configure`).",
)
@click.argument("pytest_args", nargs=-1, type=click.UNPROCESSED)
def test(packages_select: tuple[str, ...], workspace: Path | None, pytest_args: tuple[str, ...]) -> None:
    """Run the tests of the workspace's behavior packages with Kinema's pytest plugin.

    Each package's tests run in their own pytest process from the package folder, with the fixtures of
    kinema.testing (tick_behavior, build_tree, run_objective, kinema_node, package_registry). Extra
    arguments after `--` go to pytest, e.g. `kinema test -- -k adds -x`. Exits 1 if any test fails.
    """
    import subprocess

    from kinema.cli.options import resolve_selection
    from kinema.plugins.dependencies import workspace_behavior_packages

    _require_pytest()
    found, _ = resolve_selection(workspace, None, need_config=False)
    if found.root is None:
        from kinema.config.workspace import select_workspace_hint

        raise KinemaError(f"no workspace is selected: {select_workspace_hint()}")
    packages = workspace_behavior_packages(found.root, packages_select)
    if not packages:
        click.echo(f"no behavior packages in {found.root / 'src'} (create one with `kinema new behavior`)")
        return
    failed: list[str] = []
    plugin_args = [] if _plugin_installed() else ["-p", "kinema.testing.plugin"]
    for package in packages:
        if not package.has_tests:
            click.echo(f"{package.name}: no tests/ folder, skipped")
            continue
        click.secho(f"== {package.name} ({package.path})", bold=True)
        command = [sys.executable, "-m", "pytest", *plugin_args, *pytest_args]
        if subprocess.run(command, cwd=package.path).returncode != 0:
            failed.append(package.name)
    if failed:
        click.secho(f"tests failed in: {', '.join(failed)}", err=True, fg="red")
        raise click.exceptions.Exit(1)
    count = len(packages)
    click.secho(f"all tests passed ({count} package{'' if count == 1 else 's'})", fg="green")


def _require_pytest() -> None:
    """Say which command installs pytest when this Python has none (an install with --no-deps skips it)."""
    import importlib.util
    import shlex

    if importlib.util.find_spec("pytest") is None:
        python = shlex.quote(sys.executable)
        raise KinemaError(
            f"`kinema test` runs pytest, which is not installed for {sys.executable}; install it with: "
            f"{python} -m pip install 'pytest>=8'"
        )


def _plugin_installed() -> bool:
    from importlib import metadata

    return any(entry.name == "kinema" for entry in metadata.entry_points(group="pytest11"))


def _count(number: int, noun: str) -> str:
    """``1 problem``, ``2 problems``."""
    return f"{number} {noun}{'' if number == 1 else 's'}"
