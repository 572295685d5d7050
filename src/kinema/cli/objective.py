"""``kinema objective``: the objectives of a config (``list``, ``show``; running comes with the runtime)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from kinema.cli.groups import VerbGroup
from kinema.cli.options import (
    print_notices,
    print_warnings,
    refuse_other_config,
    resolve_selection,
    running_selection,
    selection_options,
    verbose_option,
)

if TYPE_CHECKING:
    from kinema.config import ObjectiveLibrary


@click.group(cls=VerbGroup)
def objective() -> None:
    """List, inspect and run the objectives of a config package.

    `list` and `show` read the objective files of the config that `-c` or $KINEMA_CONFIG names, else of
    the config the runtime on this machine runs (`kinema run -c NAME`, at the router these verbs join),
    else of the one `kinema configure` stored.
    """


def _load_library(workspace: Path | None, config: str | None, verbose: bool) -> ObjectiveLibrary:
    from kinema.config import ObjectiveLibrary, resolve_config

    running = running_selection(workspace, config)
    if running is not None:
        workspace, config, note = running
        click.secho(f"note: {note}", err=True, fg="yellow")
    found, name = resolve_selection(workspace, config)
    resolved = resolve_config(name, found)
    library = ObjectiveLibrary.load(resolved)
    print_warnings([*resolved.warnings, *library.warnings])
    if verbose:
        print_notices([*resolved.notices, *library.notices])
    return library


@objective.command("list")
@selection_options
@click.option(
    "--json",
    "as_json",
    is_flag=True,
    help='Print {"config", "objectives": [...], "errors": [...], "cannot_load": {id: reason}}.',
)
@click.option(
    "--no-check", is_flag=True, help="Do not load the config's behaviors to check which objectives can load."
)
@verbose_option
def list_(workspace: Path | None, config: str | None, as_json: bool, no_check: bool, verbose: bool) -> None:
    """List the objectives of the config's objective libraries, and which of them cannot load and why.

    Columns: R = offered to run (- for a subtree-only objective: the UI does not offer it, but
    `objective run NAME -p PORT=VALUE` runs it), * = favorite, ! = cannot load. Each objective
    that cannot load (its file or a SubTree it reaches does not validate against the config's behaviors)
    is listed after the table, one line each, with the first problem as file:line: message. Files that
    cannot be read are reported as file:line: message on stderr; the other objectives are still listed.
    The check's answer is kept in the user cache folder and reused until an objective file, a behavior
    package's source or Kinema itself changes.
    """
    import json

    library = _load_library(workspace, config, verbose)
    objectives = library.sorted()
    problems = {} if no_check else _load_problems(library)
    if as_json:
        payload = {
            "config": library.resolved.name if library.resolved else None,
            "objectives": [info.to_json() for info in objectives],
            "errors": [str(error) for error in library.errors],
            "cannot_load": problems,
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
        if problems:  # the third column only when something cannot load, so the usual table keeps its shape
            flags += "!" if info.id in problems else " "
        click.echo(f"{flags} {info.id:<{width}}  {info.subcategory or '-':<{category_width}}  {info.package}")
    if problems:
        click.echo(f"\n{len(problems)} of {len(objectives)} objectives cannot load:")
        for objective_id, problem in problems.items():
            click.echo(f"  {objective_id}: {problem}")


def _load_problems(library: ObjectiveLibrary) -> dict[str, str]:
    """Objective ID -> why it cannot load, against the behaviors the config loads.

    The answer of the last check is reused while nothing it depends on changed (see
    :mod:`kinema.runtime.library_check`).
    """
    from kinema.plugins import BehaviorHost
    from kinema.runtime.library_check import LibraryCheckCache, check_fingerprint, library_problems

    if library.resolved is None:
        return {}
    host = BehaviorHost.for_config(library.resolved)
    specs, report = host.select()
    cache = LibraryCheckCache(library.resolved.name, host.workspace)
    fingerprint = check_fingerprint(library, specs)
    problems = None if report.errors else cache.get(fingerprint)
    if problems is None:
        loaded = host.load_specs(specs)
        report.errors.extend(loaded.errors)
        problems = library_problems(library, host.registry.create_factory())
        if not report.errors:
            cache.put(fingerprint, problems)
    for error in report.errors:
        click.secho(f"warning: {error}", err=True, fg="yellow")
    return problems


@objective.command()
@click.argument("name")
@selection_options
@click.option("--xml", "as_xml", is_flag=True, help="Print only the XML file of the objective.")
@click.option("--json", "as_json", is_flag=True, help="Print the objective's metadata and ports as JSON.")
@verbose_option
def show(
    name: str, workspace: Path | None, config: str | None, as_xml: bool, as_json: bool, verbose: bool
) -> None:
    """Show one objective: source file, metadata, parameters (ports) and XML.

    The ports listed are what `-p NAME=VALUE` can set (the subtree ports the objective declares, then
    the blackboard keys its behaviors read), with their types, followed by its declared outputs: the
    same list the SDK's `objectives()` and the terminal UI's override form give. A run without `-p`
    for a port starts from the default shown.
    """
    import json
    from dataclasses import replace

    from kinema.config.cell import config_default_key, config_default_value
    from kinema.config.objective_parameters import objective_interface

    library = _load_library(workspace, config, verbose)
    info = library.get(name)
    if as_xml:
        click.echo(info.read_xml(), nl=False)
        return
    info = replace(info, ports=objective_interface(info, _behavior_factory(library, verbose)))
    if as_json:
        click.echo(json.dumps({**info.to_json(), "xml": info.read_xml()}, indent=2))
        return
    click.echo(f"{info.id}")
    click.echo(f"  file:        {info.location}")
    click.echo(f"  package:     {info.package}")
    click.echo(f"  description: {info.description or '-'}")
    click.echo(f"  subcategory: {info.subcategory or '-'}")
    subtree_only = "no (a subtree: the UI does not offer it; `objective run` runs it from its defaults)"
    click.echo(f"  runnable:    {'yes' if info.runnable else subtree_only}")
    click.echo(f"  favorite:    {'yes' if info.favorite else 'no'}")
    for path in info.shadows:
        click.echo(f"  shadows:     {path}")
    if info.ports:
        click.echo("  ports:")
        width = max(len(port.name) for port in info.ports)
        type_width = max(len(port.type_name or "-") for port in info.ports)
        for port in info.ports:
            if port.default is not None and config_default_key(str(port.default)) is not None:
                # What a run starts from: the config's value now (none when the config does not set it).
                value = config_default_value(str(port.default), library.resolved)
                default = f" = {value or '(none: the config does not set it)'}  [from {port.default}]"
            elif port.default is not None and str(port.default).strip():
                default = f" = {port.default}"
            elif port.direction != "output":
                # Not "= " and nothing: a run that reads it without a value fails there.
                default = f" = (none; -p {port.name}=VALUE sets it)"
            else:
                default = ""
            description = f"  ({port.description})" if port.description else ""
            type_name = f"{port.type_name or '-':<{type_width}}"
            click.echo(f"    {port.direction:<6} {port.name:<{width}}  {type_name}{default}{description}")
    else:
        click.echo("  ports:       none")
    click.echo("")
    click.echo(info.read_xml(), nl=False)


def _behavior_factory(library: ObjectiveLibrary, verbose: bool) -> object:
    """The config's behaviors and the library's subtrees in one factory, as the agent builds it.

    Only read for the ports' directions and types; behaviors that fail to load are reported, not fatal.
    """
    from kinema.errors import KinemaError
    from kinema.plugins import BehaviorHost

    resolved = library.resolved
    if resolved is None:
        return None
    host = BehaviorHost.for_config(resolved)
    report = host.load()
    if verbose:
        for error in report.errors:
            click.secho(f"warning: {error}", err=True, fg="yellow")
    factory = host.registry.create_factory()
    for path in library.files():
        try:
            factory.register_behavior_tree_from_file(path)
        except KinemaError:
            pass  # reported by `kinema objective list`; this objective's own file is what matters
    return factory


@objective.command("check")
@click.argument("folder", type=click.Path(exists=True, file_okay=False, path_type=Path))
@selection_options
@click.option(
    "--run",
    "run_them",
    is_flag=True,
    help="Also run each runnable objective on the config's simulation, headless, one at a time.",
)
@click.option(
    "--subtrees",
    "subtree_folders",
    multiple=True,
    type=click.Path(exists=True, file_okay=False, path_type=Path),
    metavar="DIR",
    help="A folder of objectives the checked ones reach through SubTrees (not counted); repeatable.",
)
@click.option(
    "--only", multiple=True, metavar="NAME", help="Run only this runnable objective (repeatable; with --run)."
)
@click.option(
    "--time-limit",
    type=click.FloatRange(min=1.0),
    default=120.0,
    show_default=True,
    metavar="SECONDS",
    help="Simulated seconds an objective may run before it is cancelled (and counts as kept running).",
)
@click.option(
    "--sim-speed",
    default="max",
    show_default=True,
    metavar="FACTOR|max",
    help="Simulated seconds per wall second while the objectives run.",
)
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON (counts, files, runs).")
def check(
    folder: Path,
    workspace: Path | None,
    config: str | None,
    run_them: bool,
    subtree_folders: tuple[Path, ...],
    only: tuple[str, ...],
    time_limit: float,
    sim_speed: str,
    as_json: bool,
) -> None:
    """Count how many objective files of FOLDER validate and, with --run, how many runnable ones succeed.

    FOLDER holds objective XML files (or is a package with an objectives/ folder, as MoveIt Pro's
    config packages are). They are checked against a config package (-c; default the selected one,
    else lab_sim): its behaviors, core subtrees, waypoints, robot and simulation. A copy of FOLDER is
    checked, so files the objectives save never land in it.

    With --run, a headless runtime of the config starts (simulation at --sim-speed, approvals granted as
    with `kinema run --auto-approve`) and runs each runnable objective in turn, after putting the cell
    back as it started: the folder's files as shipped, the simulation's keyframe, the startup
    controllers, an empty planning scene. One still running without failure after --time-limit
    simulated seconds (and at least 30 wall seconds), a loop such as "3 Waypoints Pick and Place", is
    cancelled and counts as succeeding ("kept running").

    Prints a line per file that does not validate and per objective run, then the counts. Exits 0 only
    when every file validates and, with --run, every runnable objective succeeds.
    """
    import json

    from kinema.cli.options import resolve_selection
    from kinema.drivers.mujoco.sim_speed import parse_sim_speed
    from kinema.runtime.objective_check import FileVerdict, RunVerdict, check_folder

    if only and not run_them:
        raise click.UsageError("--only names objectives to run: give --run too")
    parse_sim_speed(sim_speed)
    found, name = resolve_selection(workspace, config, need_config=False)
    name = name or "lab_sim"
    root = getattr(found, "root", None)

    def on_file(verdict: FileVerdict) -> None:
        if as_json:
            return
        if verdict.problem is not None:
            click.echo(f"cannot load  {verdict.path}: {verdict.problem.splitlines()[0]}")
        print_warnings(verdict.warnings)

    def on_run(verdict: RunVerdict) -> None:
        if as_json:
            return
        seconds = f"{verdict.sim_seconds:.0f} s sim, {verdict.wall_seconds:.0f} s wall"
        if verdict.outcome == "cannot load":
            return  # said above, with its file
        if verdict.ok:
            click.echo(f"{verdict.outcome:<12} {verdict.objective} ({seconds})")
        else:
            message = verdict.message.splitlines()[0] if verdict.message else ""
            click.secho(f"{'failed':<12} {verdict.objective} ({seconds}): {message}", fg="red")

    report = check_folder(
        folder,
        name,
        workspace=Path(root) if root is not None else None,
        subtree_folders=subtree_folders,
        run=run_them,
        time_limit=time_limit,
        only=only,
        sim_speed=sim_speed,
        on_file=on_file,
        on_run=on_run,
        echo=None if as_json else (lambda text: click.echo(text, err=True)),
    )
    counts = report.counts()
    if as_json:
        click.echo(json.dumps(report.to_json(), indent=2))
    else:
        click.echo(report.summary())
    if counts["valid"] < counts["files"] or any(not run.ok for run in report.runs or ()):
        raise click.exceptions.Exit(1)


# -- running objectives on a live runtime (run, cancel, do, status) ------------------------------------

running_config_option = click.option(
    "--config",
    "-c",
    "config",
    metavar="NAME",
    default=None,
    help="The config package the running runtime must serve (the command refuses to run on another).",
)
connect_option = click.option(
    "--connect",
    "-e",
    default=None,
    metavar="ENDPOINT",
    help="Router to join (default: $KINEMA_ZENOH_CONNECT, else the endpoint of $KINEMA_ZENOH_CONFIG, else "
    "tcp/127.0.0.1:7447).",
)
timeout_option = click.option(
    "--timeout",
    type=float,
    default=5.0,
    show_default=True,
    metavar="SECONDS",
    help="How long to wait for a runtime to answer before giving up.",
)


def _client(connect: str | None, timeout: float):  # type: ignore[no-untyped-def]
    # The JSON client: no ROS type system to load, so one-shot commands start fast.
    from kinema.sdk.quick import QuickClient

    return QuickClient(connect, timeout=timeout)


def _show_toast(level: str, text: str) -> None:
    """Print a behavior's message to the UI; failures are left to the result line, which carries them."""
    if level == "warn":
        click.secho(f"warning: {text}", err=True, fg="yellow")
    elif level != "failure":
        click.echo(text)


@contextmanager
def _terminating_interrupts() -> Iterator[None]:
    """SIGTERM and SIGHUP act as Ctrl-C meanwhile: `timeout 60 kinema objective run ...`, a script that
    kills the command or a closed terminal cancel the objective; the robot does not go on moving for a
    command that is gone. Restored before the cancel, so a second signal ends the command at once."""
    import signal

    def interrupt(_signum: int, _frame: object) -> None:
        raise KeyboardInterrupt

    caught = [sig for sig in (signal.SIGTERM, getattr(signal, "SIGHUP", None)) if sig is not None]
    previous = {sig: signal.signal(sig, interrupt) for sig in caught}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _finish(run, wait: bool, source: str = "") -> None:  # type: ignore[no-untyped-def]
    """Wait for a started objective (Ctrl-C, SIGTERM or SIGHUP cancels it) and exit 0 only when it
    succeeded.

    ``source``: the file the objective's XML came from, named in its messages instead of the runtime's
    ``<objective XML>`` (which only ever saw the text).
    """
    if not wait:
        click.echo(f"started {run.objective_name!r}")
        return
    try:
        with _terminating_interrupts():
            result = run.result(on_toast=_show_toast)
    except KeyboardInterrupt:
        click.echo(f"cancelling {run.objective_name!r} ...", err=True)
        run.cancel()
        result = run.result(on_toast=_show_toast)
    text = str(result).replace("<objective XML>", source) if source else str(result)
    if result.succeeded:
        click.echo(text)
        return
    click.secho(text, err=True, fg="yellow" if result.cancelled else "red")
    raise click.exceptions.Exit(1)


@objective.command("run")
@click.argument("name")
@click.option(
    "-p",
    "--param",
    "params",
    multiple=True,
    metavar="NAME=VALUE",
    help="Override a parameter (VALUE is YAML, parsed into the port's type); repeatable.",
)
@click.option("--no-wait", is_flag=True, help="Return once the objective started instead of when it ends.")
@running_config_option
@connect_option
@timeout_option
def run_(
    name: str, params: tuple[str, ...], no_wait: bool, config: str | None, connect: str | None, timeout: float
) -> None:
    """Run objective NAME on the running Kinema (a running objective is preempted).

    Prints the messages its behaviors publish for the UI (toasts) while it runs. Exits 0 when the
    objective succeeds, 1 when it fails or is cancelled; Ctrl-C cancels it, and so does SIGTERM (as
    `timeout` sends it) or a closed terminal.
    """
    from kinema.sdk import ParameterOverride

    overrides = [ParameterOverride.parse(param) for param in params]
    with _client(connect, timeout) as client:
        _check_running_config(client, config)
        _finish(client.start(name, overrides), not no_wait)


@objective.command("do")
@click.argument("file", type=click.File("r"))
@click.option("--no-wait", is_flag=True, help="Return once the objective started instead of when it ends.")
@running_config_option
@connect_option
@timeout_option
def do_(file, no_wait: bool, config: str | None, connect: str | None, timeout: float) -> None:  # type: ignore[no-untyped-def]
    """Run the BT.CPP v4 XML in FILE (`-` reads stdin) as an ad-hoc objective (its main tree)."""
    xml = file.read()
    source = "" if file.name == "<stdin>" else file.name
    with _client(connect, timeout) as client:
        _check_running_config(client, config)
        _finish(client.start(xml=xml), not no_wait, source)


def _check_running_config(client: Any, config: str | None) -> None:
    """With ``-c NAME``: refuse to run on a runtime that serves another config."""
    if config:
        refuse_other_config(
            client.runtime_configs(), config, "an objective of that name would move its robot"
        )


@objective.command("cancel")
@connect_option
@timeout_option
def cancel_(connect: str | None, timeout: float) -> None:
    """Cancel the objective that is running.

    It ends as cancelled (MoveIt's error code PREEMPTED): its running behaviors are halted.
    """
    with _client(connect, timeout) as client:
        cancelled, name = client.cancel()
    click.echo(f"cancelled {name!r}" if cancelled else "no objective was running")


@objective.command("status")
@click.option("-f", "--follow", is_flag=True, help="Keep printing every status change (Ctrl-C stops).")
@click.option("--json", "as_json", is_flag=True, help="Print each status as one JSON object.")
@connect_option
@timeout_option
def status_(follow: bool, as_json: bool, connect: str | None, timeout: float) -> None:
    """Print the objective server's status: Idle, Loading, Running, Success, Failure or Cancelled."""
    import dataclasses
    import json

    def show(status) -> None:  # type: ignore[no-untyped-def]
        if as_json:
            click.echo(
                json.dumps({k: str(v) if k == "status" else v for k, v in dataclasses.asdict(status).items()})
            )
        else:
            click.echo(str(status))

    if not follow:
        with _client(connect, timeout) as quick:
            status, name, warnings = quick.status_report()
        if as_json:
            click.echo(json.dumps({"status": str(status), "objective_name": name, "warnings": warnings}))
        else:
            click.echo(f"{status}: {name}" if name else str(status))
            for warning in warnings:  # the watchdog: a behavior stuck in tick, an abandoned thread
                click.secho(f"warning: {warning}", fg="red")
        return
    from kinema.sdk import ObjectiveClient

    with ObjectiveClient(connect, timeout=timeout) as client:
        current = client.status()
        show(current)
        last = (current.status, current.objective_name)
        try:
            # Heartbeats stop when the runtime goes away; say so instead of waiting forever.
            for heartbeat in client.statuses(timeout=max(timeout, 2.0)):
                if (heartbeat.status, heartbeat.objective_name) != last:
                    last = (heartbeat.status, heartbeat.objective_name)
                    show(heartbeat)
        except KeyboardInterrupt:
            return
        click.secho("the runtime stopped sending heartbeats", err=True, fg="red")
        raise click.exceptions.Exit(1)
