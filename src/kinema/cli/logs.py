"""``kinema logs`` and ``kinema export-logs``: read and archive the logs of the latest run."""

from __future__ import annotations

import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING

import click

if TYPE_CHECKING:
    from kinema.runtime.run_folder import RunFolder

#: How often `kinema logs -f` looks whether its run still runs (seconds).
RUN_CHECK_S = 0.5
_RUN_HELP = "A run folder name (see the state folder's runs/) instead of the newest run."


def _run_folder(run_name: str | None) -> RunFolder:
    from kinema.errors import KinemaError, did_you_mean
    from kinema.runtime.run_folder import RunFolder, list_runs

    if run_name is None:
        return RunFolder.latest()
    runs = {run.name: run for run in list_runs()}
    if run_name not in runs:
        raise KinemaError(f"no run named {run_name!r}; {did_you_mean(run_name, runs)}")
    return runs[run_name]


@click.command()
@click.option(
    "-f",
    "--follow",
    is_flag=True,
    help="Keep printing new entries as they come, until the run stops (or Ctrl-C).",
)
@click.option(
    "--level",
    default="debug",
    show_default=True,
    metavar="LEVEL",
    help="Only entries at or above this level: debug, info, warning, error, critical.",
)
@click.option("--run", "run_name", default=None, metavar="NAME", help=_RUN_HELP)
@click.option(
    "--recordings",
    "list_recordings",
    is_flag=True,
    help="List the run's objective recordings (.btlog files: open them in Groot2 or `kinema ui`) "
    "instead of its logs.",
)
def logs(follow: bool, level: str, run_name: str | None, list_recordings: bool) -> None:
    """Print the logs of the latest `kinema run` (agent, drivers, supervisor), merged in time order."""
    from kinema.process.log_files import follow_entries, level_number, merged_entries

    if list_recordings:
        _print_recordings(_run_folder(run_name))
        return
    try:
        min_level = level_number(level)
    except ValueError as error:
        raise click.BadParameter(str(error), param_hint="--level") from None
    folder = _run_folder(run_name)
    for entry in merged_entries(folder.log_files(), min_level=min_level):
        click.echo(entry.text)
    if follow:
        stop = threading.Event()
        threading.Thread(target=_stop_when_the_run_ends, args=(folder, stop), daemon=True).start()
        try:
            for entry in follow_entries(folder.path, min_level=min_level, stop=stop):
                click.echo(entry.text)
        except KeyboardInterrupt:
            return
        click.echo(f"(run {folder.name} ended)", err=True)


def _stop_when_the_run_ends(folder: RunFolder, stop: threading.Event) -> None:
    """Set ``stop`` once no live `kinema run` writes into ``folder`` (a moment later, so that its last
    entries are read): following a run that ended would wait for ever."""
    from kinema.runtime.instance import running_instances

    def live() -> bool:
        where = str(folder.path)
        return any(record.run_folder == where for record in running_instances())

    while live():
        time.sleep(RUN_CHECK_S)
    time.sleep(2 * RUN_CHECK_S)  # the follower reads the run's last lines meanwhile
    stop.set()


def _print_recordings(folder: RunFolder) -> None:
    from kinema.bt.btlog import BtlogError, read_btlog
    from kinema.runtime.recordings import FOLDER_NAME, list_recordings

    files = list_recordings(folder.path / FOLDER_NAME)
    if not files:
        click.echo(
            f"no recordings in {folder.path / FOLDER_NAME} (runs started with --no-record are not recorded)"
        )
        return
    rows = []
    for file in files:
        name = file.objective_name
        try:
            recording = read_btlog(file.path)
            count = f"{len(recording.transitions)} transitions"
            name = recording.tree_id or name
        except BtlogError as error:
            count = f"unreadable: {error}"
        rows.append((name, count, file))
    width = max(len(name) for name, _, _ in rows)
    for name, count, file in rows:
        click.echo(f"{name:<{width}}  {count:>17}  {file.size / 1024:8.1f} kB  {file.path}")


@click.command("export-logs")
@click.option(
    "-o",
    "--output",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="The zip file to write (default: kinema-logs-<run>.zip in the current folder).",
)
@click.option("--run", "run_name", default=None, metavar="NAME", help=_RUN_HELP)
def export_logs(output: Path | None, run_name: str | None) -> None:
    """Zip the log folder of the latest run, objective recordings included (to attach to a bug report).

    Only the run folder's own files go in: symbolic links (which could point anywhere on the machine)
    are skipped and listed.
    """
    import zipfile

    folder = _run_folder(run_name)
    target = output if output is not None else Path.cwd() / f"kinema-logs-{folder.name}.zip"
    files = folder.files()
    try:
        with zipfile.ZipFile(target, "w", compression=zipfile.ZIP_DEFLATED) as archive:
            for path in files:
                archive.write(path, Path(folder.name) / path.relative_to(folder.path))
    except OSError as error:
        from kinema.errors import KinemaError

        raise KinemaError(f"cannot write {target}: {error.strerror or error}") from None
    for link in folder.links():
        click.echo(
            f"skipped {link.relative_to(folder.path)}: a symbolic link, not a file of the run", err=True
        )
    click.echo(f"wrote {target} ({len(files)} files from {folder.path})")
