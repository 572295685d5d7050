"""``kinema new``: generate packages from Kinema's templates."""

from __future__ import annotations

from pathlib import Path

import click

from kinema.cli.groups import VerbGroup
from kinema.cli.options import workspace_option
from kinema.scaffold.names import BEHAVIOR_TYPES


@click.group(cls=VerbGroup)
def new() -> None:
    """Generate a new package: from a template, or a robot's config package from its URDF."""


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
@click.option(
    "--from-urdf",
    "urdf",
    type=str,
    metavar="URDF",
    default=None,
    help="Make the package for your own robot from its URDF or .xacro, a path or package://PKG/PATH.",
)
@click.option(
    "--srdf",
    type=str,
    metavar="SRDF",
    default=None,
    help="With --from-urdf: the robot's SRDF (planning groups, group states, end effector).",
)
@click.option(
    "--mjcf",
    type=str,
    metavar="MJCF",
    default=None,
    help="With --from-urdf: a MuJoCo scene to simulate it in (default: one is generated).",
)
@click.option(
    "--xacro-arg",
    "xacro_args",
    multiple=True,
    metavar="NAME:=VALUE",
    help="With --from-urdf: an argument of the .xacro (repeatable).",
)
def new_config(
    name: str | None,
    package_name: str | None,
    based_on: str | None,
    output_dir: Path | None,
    workspace: Path | None,
    no_input: bool,
    urdf: str | None,
    srdf: str | None,
    mjcf: str | None,
    xacro_args: tuple[str, ...],
) -> None:
    """Create config package NAME based on PARENT, or for your own robot with --from-urdf.

    The package gets config/config.yaml with based_on_package, its own objectives/ folder registered
    under objective_library_paths, and package.xml. Nothing is written when the name is invalid or
    taken, the parent is unknown or the folder exists.

    With --from-urdf URDF [--srdf SRDF] [--mjcf MJCF] it is a package for that robot, based on
    kinema_base (Kinema's core behaviors and subtrees): the URDF (xacro expanded; package:// found in
    the workspace, ROS_PACKAGE_PATH, AMENT_PREFIX_PATH and pip-installed description packages), the SRDF
    (or one planning group over the URDF's longest chain), a MuJoCo scene with the robot on a table
    (DAE meshes converted), joint limits, waypoints (Home and the SRDF's group states) and, for a
    gripper, Open/Close Gripper. config.yaml says what was chosen; `kinema build -c NAME` checks it and
    `kinema run -c NAME` simulates it.
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
    if urdf is None and (srdf or mjcf or xacro_args):
        raise ScaffoldError("--srdf, --mjcf and --xacro-arg go with --from-urdf URDF")
    if urdf is not None:
        if based_on is not None:
            raise ScaffoldError(
                "a package made --from-urdf is based on kinema_base (Kinema's core behaviors and "
                "subtrees); leave out --based-on"
            )
        if name is None:
            raise ScaffoldError("the package name is missing: kinema new config NAME --from-urdf URDF")
        _new_robot_config(name, urdf, srdf, mjcf, xacro_args, output_dir, found, workspace)
        return
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


def _new_robot_config(
    name: str,
    urdf: str,
    srdf: str | None,
    mjcf: str | None,
    xacro_args: tuple[str, ...],
    output_dir: Path | None,
    found: object,
    workspace: Path | None,
) -> None:
    """``kinema new config NAME --from-urdf URDF``: write the package and say what was decided."""
    import time

    from kinema.errors import ScaffoldError
    from kinema.scaffold.robot_package import new_robot_package

    arguments: dict[str, str] = {}
    for item in xacro_args:
        key, sep, value = item.partition(":=")
        if not sep or not key.strip():
            raise ScaffoldError(f"--xacro-arg {item!r} is not NAME:=VALUE")
        arguments[key.strip()] = value
    started = time.monotonic()
    path, plan = new_robot_package(
        name,
        urdf,
        srdf=srdf,
        mjcf=mjcf,
        xacro_args=arguments,
        output_dir=output_dir,
        workspace=found,  # type: ignore[arg-type]
        progress=lambda text: click.echo(f"... {text}", err=True),
    )
    click.echo(f"created config package {name} in {path} ({time.monotonic() - started:.1f} s)")
    gripper = (
        f"{plan.gripper_joint}: open {plan.gripper_open:g}, closed {plan.gripper_closed:g}"
        if plan.gripper_joint
        else "none"
    )
    for label, value in (
        ("robot", f"{plan.robot.name} ({len(plan.robot.meshes)} meshes)"),
        ("planning group", f"{plan.planning_group}: {', '.join(plan.group_joints)}"),
        ("tool frame", plan.tool_frame),
        ("gripper", gripper),
        ("waypoints", ", ".join(plan.waypoints)),
    ):
        click.echo(f"  {label:<15} {value}")
    for note in plan.notes:
        click.echo(f"  note: {note}")
    where = "" if workspace is None else f" -w {workspace}"
    click.echo(f"try: kinema build -c {name}{where}, then kinema run -c {name}{where}")


@new.command("behavior")
@click.argument("name")
@click.option(
    "-t",
    "--type",
    "behavior_type",
    type=click.Choice(BEHAVIOR_TYPES),
    default="async",
    show_default=True,
    help="The base class: sync (one tick), stateful (over several ticks, on the tick thread), async (work "
    "off the tick thread), service_client (AddTwoInts), action_client (Fibonacci), topic_subscriber / "
    "topic_publisher (std_msgs/String).",
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
