"""Options shared by the verbs that work on a workspace and a config package.

``-w/--workspace`` and ``-c/--config`` take precedence over ``KINEMA_WORKSPACE``/``KINEMA_CONFIG`` and
over what ``kinema configure`` stored (see :func:`kinema.config.active_selection`). A verb decorated
with :func:`selection_options` receives ``workspace`` and ``config`` arguments; :func:`resolve_selection`
turns them into a :class:`~kinema.config.Workspace` and a config name.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any, TypeVar

import click

F = TypeVar("F", bound=Callable[..., Any])

workspace_option = click.option(
    "-w",
    "--workspace",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    help="Workspace folder (default: $KINEMA_WORKSPACE, else the one set with `kinema configure`).",
)
config_option = click.option(
    "-c",
    "--config",
    default=None,
    metavar="NAME",
    help="Config package (default: $KINEMA_CONFIG, else the one set with `kinema configure`).",
)
verbose_option = click.option(
    "-v", "--verbose", is_flag=True, help="Also print notices: unknown keys, overlays, shadowed objectives."
)


def selection_options(function: F) -> F:
    """Add ``-w/--workspace`` and ``-c/--config`` to a click command."""
    return workspace_option(config_option(function))


def resolve_selection(
    workspace: Path | None, config: str | None, *, need_config: bool = True
) -> tuple[Any, str]:
    """Return the :class:`~kinema.config.Workspace` and config name a verb should use.

    Raises:
        ConfigError: no config is selected (when ``need_config``), or the workspace is not one.
    """
    from kinema.config import Workspace, active_selection

    selection = active_selection(workspace, config)
    found = Workspace.discover(selection.workspace) if selection.workspace else Workspace.bundled_only()
    name = selection.require_config() if need_config else (selection.config or "")
    return found, name


def running_selection(workspace: Path | None, config: str | None) -> tuple[Path | None, str, str] | None:
    """The workspace and config of the runtime running on this machine at the router the verbs join, with
    a note saying so, when nothing chooses another (no ``-w``/``-c``, no ``KINEMA_WORKSPACE``/
    ``KINEMA_CONFIG``) and it runs another config than the stored one (``kinema run -c NAME``).

    None when no such runtime runs, or when it runs the selected config.
    """
    from kinema.config import active_selection

    selection = active_selection(workspace, config)
    if selection.config_source in ("flag", "environment") or selection.workspace_source in (
        "flag",
        "environment",
    ):
        return None
    from kinema.runtime.instance import running_instances
    from kinema.transport.session import resolve_endpoints

    endpoint = resolve_endpoints(None)[0]
    runs = [r for r in running_instances() if r.router == endpoint and r.config]
    if len(runs) != 1:
        return None
    run = runs[0]
    run_workspace = Path(run.workspace) if run.workspace else None
    if run.config == selection.config and run_workspace in (None, selection.workspace):
        return None
    note = (
        f"config {run.config}: what the runtime at {endpoint} runs (kinema run pid {run.pid}); "
        f"the selected config is {selection.config} (-c chooses)"
    )
    return run_workspace, run.config, note


def print_warnings(warnings: Iterable[str]) -> None:
    """Print warnings (shown without ``-v``) on stderr."""
    for warning in warnings:
        click.secho(f"warning: {warning}", err=True, fg="yellow")


def print_notices(notices: list[str]) -> None:
    """Print verbose-mode notices on stderr."""
    for notice in notices:
        click.secho(f"note: {notice}", err=True, fg="yellow")


def refuse_other_config(running: Iterable[str], config: str | None, why: str) -> None:
    """With ``-c NAME`` given (``config``): refuse when the running runtime serves other configs
    (``running``: none known, nothing refused), ``why`` saying what would go wrong, and how to switch."""
    serving = sorted(set(running))
    if config and serving and config not in serving:
        raise click.ClickException(
            f"the running runtime serves config {', '.join(serving)}, not {config} ({why}): stop it "
            f"(`kinema down`) and start `kinema run -c {config}`, or leave out -c"
        )
