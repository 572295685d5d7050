"""The record a running ``kinema run`` leaves behind, so ``kinema down`` can find and stop it.

Each supervisor writes ``<state>/kinema/instances/<pid>.json`` (its pid, its children, the router it
hosts or joined, its run folder) and removes it when it exits. A record whose process is gone is stale
and ignored (and cleaned up). ``kinema down`` sends SIGTERM to each live supervisor, which stops its
agent and drivers before exiting; a supervisor that does not exit in time is killed together with the
children it recorded, so no process is left behind.
"""

from __future__ import annotations

import json
import os
import signal
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

from kinema.errors import KinemaError
from kinema.process.log_files import STACKS_SIGNAL
from kinema.runtime.run_folder import state_dir

STACKS_WAIT_S = 0.5
"""How long the processes of a run that did not stop get to write their stacks before they are killed."""


def instances_dir() -> Path:
    """The folder of instance records."""
    path = state_dir() / "instances"
    path.mkdir(parents=True, exist_ok=True)
    return path


@dataclass
class InstanceRecord:
    """One running ``kinema run``.

    Attributes:
        pid: the supervisor's process id.
        router: the zenoh endpoint every client connects to.
        run_folder: the run's log folder.
        config: the config package that runs.
        workspace: the workspace it was started with ("" when none was given).
        started: wall time the instance started (seconds since the epoch).
        children: process ids of the agent and the drivers.
    """

    pid: int
    router: str
    run_folder: str
    config: str = ""
    workspace: str = ""
    started: float = field(default_factory=time.time)
    children: list[int] = field(default_factory=list)

    @property
    def path(self) -> Path:
        """Where the record is stored."""
        return instances_dir() / f"{self.pid}.json"

    def save(self) -> None:
        """Write (or rewrite) the record atomically."""
        tmp = self.path.with_suffix(".tmp")
        tmp.write_text(json.dumps(asdict(self), indent=2))
        os.replace(tmp, self.path)

    def remove(self) -> None:
        """Delete the record (the instance has stopped)."""
        self.path.unlink(missing_ok=True)


def pid_alive(pid: int) -> bool:
    """True if a process with this id exists and is not a zombie."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return True


def running_instances() -> list[InstanceRecord]:
    """Records of live instances, oldest first; stale records are deleted."""
    records = []
    for path in sorted(instances_dir().glob("*.json")):
        try:
            record = InstanceRecord(**json.loads(path.read_text()))
        except (OSError, ValueError, TypeError):
            path.unlink(missing_ok=True)
            continue
        if pid_alive(record.pid):
            records.append(record)
        else:
            path.unlink(missing_ok=True)
    records.sort(key=lambda r: r.started)
    return records


def stop_instance(record: InstanceRecord, *, timeout: float = 15.0) -> bool:
    """Stop one instance: SIGTERM, wait, then SIGKILL it and its recorded children.

    Before the kill, each process writes its threads' stacks to the end of its log (in the run folder),
    so a hang can be read after the fact.

    Returns:
        True if it stopped cleanly on SIGTERM; False if it had to be killed.
    """
    try:
        os.kill(record.pid, signal.SIGTERM)
    except ProcessLookupError:
        record.remove()
        return True
    if _wait_gone([record.pid], timeout):
        _kill_leftovers(record.children)
        record.remove()
        return True
    _ask_for_stacks([record.pid, *record.children])
    _kill_leftovers([record.pid, *record.children])
    record.remove()
    return False


def stop_all(*, timeout: float = 15.0) -> list[tuple[InstanceRecord, bool]]:
    """Stop every live instance; raises KinemaError when none runs."""
    records = running_instances()
    if not records:
        raise KinemaError("no Kinema instance is running (nothing to stop)")
    return [(record, stop_instance(record, timeout=timeout)) for record in records]


def _wait_gone(pids: list[int], timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if not any(pid_alive(pid) for pid in pids):
            return True
        time.sleep(0.05)
    return not any(pid_alive(pid) for pid in pids)


def _ask_for_stacks(pids: list[int]) -> None:
    """Have each live process append every thread's stack to its log (see kinema.process.log_files)."""
    asked = False
    for pid in pids:
        if pid_alive(pid):
            try:
                os.kill(pid, STACKS_SIGNAL)
                asked = True
            except ProcessLookupError:
                pass
    if asked:
        time.sleep(STACKS_WAIT_S)


def _kill_leftovers(pids: list[int]) -> None:
    for pid in pids:
        if pid_alive(pid):
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
    _wait_gone(pids, 2.0)
