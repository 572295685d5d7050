"""``kinema run`` and ``kinema down``: start a Kinema instance (router, agent, drivers) and stop it."""

from __future__ import annotations

from pathlib import Path

import click

from kinema.cli.options import selection_options


@click.command()
@selection_options
@click.option(
    "-n", "--no-drivers", is_flag=True, help="Start only the agent (drivers run elsewhere on the network)."
)
@click.option("-o", "--only-drivers", is_flag=True, help="Start only the drivers (the agent runs elsewhere).")
@click.option(
    "--headless",
    is_flag=True,
    help="No terminal UI: just run until Ctrl-C or `kinema down` (the default when not in a terminal).",
)
@click.option("-v", "--verbose", is_flag=True, help="Log at DEBUG level and echo the supervisor's log here.")
@click.option("--no-browser", is_flag=True, help="Do not open the 3D view in a browser.")
@click.option("-l", "--list", "list_configs", is_flag=True, help="List the config packages and exit.")
@click.option(
    "--connect",
    "-e",
    default=None,
    metavar="ENDPOINT",
    help="Router endpoint(s) to host or join, comma-separated (default: $KINEMA_ZENOH_CONNECT, else "
    "tcp/127.0.0.1:7447). Beyond loopback use tls/<address>:7448 after `kinema security init`.",
)
@click.option(
    "--security",
    "security_dir",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    metavar="DIR",
    help="The folder of `kinema security init` for tls/ endpoints (default: $KINEMA_SECURITY_DIR, else "
    "~/.config/kinema/security).",
)
@click.option(
    "--insecure",
    is_flag=True,
    help="Allow a plain-text listener beyond loopback (e.g. --connect tcp/0.0.0.0:7447): anyone who reaches "
    "it can run objectives and drive the robot. Prints a warning; for trusted networks only.",
)
@click.option("--tick-rate", type=float, default=100.0, show_default=True, help="Objective ticks per second.")
@click.option(
    "--sim-speed",
    default=None,
    metavar="FACTOR|max",
    help="Simulated seconds per wall second: 1 (real time, the default), a factor such as 4, or max "
    "(as fast as the CPU allows; for tests and CI).",
)
@click.option(
    "--groot2-port",
    type=click.IntRange(1, 65534),
    default=None,
    metavar="PORT",
    help="Let Groot2 attach to the running objective: serve its protocol on 127.0.0.1 at PORT and PORT+1 "
    "(Groot2's default is 1667). Off unless given.",
)
@click.option(
    "--no-record",
    is_flag=True,
    help="Do not record objective runs (by default each run is saved as a .btlog file Groot2 replays; "
    "see `kinema logs --recordings`).",
)
@click.option(
    "--auto-approve",
    is_flag=True,
    help="Grant every approval and breakpoint without asking (WaitForMTCSolutionApproval, "
    "BreakpointSubscriber; each is logged as a warning). Without it, a headless run has no user to ask "
    "and approvals fail.",
)
def run(
    workspace: Path | None,
    config: str | None,
    no_drivers: bool,
    only_drivers: bool,
    headless: bool,
    verbose: bool,
    no_browser: bool,
    list_configs: bool,
    connect: str | None,
    security_dir: Path | None,
    insecure: bool,
    tick_rate: float,
    sim_speed: str | None,
    groot2_port: int | None,
    no_record: bool,
    auto_approve: bool,
) -> None:
    """Start Kinema: host the zenoh router (or join one), the agent and the config's drivers.

    Prints a line per driver, then one once objectives can be started (and one when it stopped), writes
    every process's log to a per-run folder (see `kinema logs`), and blocks until Ctrl-C or `kinema down`.
    One runtime per cell: when the router already has an agent (or drivers) it refuses to start another,
    and says how to join or stop it; -n and -o start the two halves of one cell.

    The network is closed by default: the router listens beyond loopback only on tls/ endpoints, with
    client certificates and access rules from `kinema security init`, or in plain text with --insecure.
    """
    from kinema.cli.options import resolve_selection

    if list_configs:
        _list_configs(workspace)
        return
    if no_drivers and only_drivers:
        raise click.UsageError("-n/--no-drivers and -o/--only-drivers exclude each other")
    if sim_speed is not None:
        from kinema.drivers.mujoco.sim_speed import parse_sim_speed

        parse_sim_speed(sim_speed)  # refuse a bad value here rather than in the driver's log
    found, name = resolve_selection(workspace, config)
    from kinema.runtime.launcher import Launcher, LaunchOptions

    if auto_approve:
        import os

        # Read by the approval behaviors in the agent process, which inherits this environment.
        os.environ["KINEMA_AUTO_APPROVE"] = "1"
        click.echo("approvals and breakpoints are granted automatically (--auto-approve)")

    ui = None
    if not headless:
        import sys

        if sys.stdin.isatty() and sys.stdout.isatty():
            from kinema.tui.launch import run_for_launcher

            ui = run_for_launcher
        else:
            click.echo("not a terminal: running headless (pass --headless to say so)")
    root = getattr(found, "root", None)
    options = LaunchOptions(
        config=name,
        workspace=Path(root) if root is not None else None,
        agent=not only_drivers,
        drivers=not no_drivers,
        endpoint=connect,
        insecure=insecure,
        security_dir=security_dir,
        verbose=verbose,
        tick_rate_hz=tick_rate,
        sim_speed=sim_speed,
        echo=click.echo,
        ui=ui,
        # The 3D view comes with the interactive runtime (the TUI); headless runs skip it.
        viewer=ui is not None and not no_browser and not only_drivers,
        groot2_port=groot2_port,
        record=not no_record,
    )
    code = Launcher(options).run()
    if code:
        raise click.exceptions.Exit(code)


def _list_configs(workspace: Path | None) -> None:
    from kinema.config import Workspace, list_config_packages

    packages = list_config_packages(Workspace.discover(workspace))
    if not packages:
        click.echo("no config packages")
        return
    width = max(len(package.name) for package in packages)
    for package in packages:
        click.echo(f"{package.name:<{width}}  {package.path}")


@click.command()
@click.option(
    "--timeout", type=float, default=15.0, show_default=True, help="Seconds to wait for a clean stop."
)
def down(timeout: float) -> None:
    """Stop every `kinema run` started with this state folder (a `kinema view` or `kinema ui` stays).

    Every `kinema run` recorded in the user's state folder ($XDG_STATE_HOME) stops cleanly, with its
    agent, drivers and router: a cell split with `kinema run -n` and `kinema run -o` stops whole.
    SIGTERM first, SIGKILL after --timeout seconds (a run that had to be killed first writes every
    thread's stack to its logs, to show where it hung). A `kinema view` or `kinema ui` started on its own
    keeps running: it shows that the runtime went away and follows the next one.
    """
    from kinema.runtime.instance import stop_all

    for record, clean in stop_all(timeout=timeout):
        what = f"kinema run (pid {record.pid}, config {record.config or '-'})"
        if clean:
            click.echo(f"stopped {what}")
        else:
            click.echo(
                f"killed (it did not stop in time) {what}; each process wrote its threads' stacks to the "
                f"end of its log in {record.run_folder}"
            )
