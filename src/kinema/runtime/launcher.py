"""``kinema run``'s supervisor: host (or join) the router, start the agent and the drivers, stop them all.

Process layout: the supervisor (the ``kinema run`` process) hosts the zenoh router and watches its
children; the agent and each driver run in processes of their own. The agent is a child rather than a
thread of the supervisor so that its 100 Hz tick thread never competes for the GIL with a UI running in
the supervisor (the TUI), so a crashing behavior cannot take the router (and every client's connection)
down with it, and so ``kinema down`` can stop it like any other process. Children get a parent-death
signal and a lifeline (:mod:`kinema.process.lifeline`), so even a supervisor killed with SIGKILL leaves
no orphans behind: they end within about a second.

A UI plugs in through :attr:`LaunchOptions.ui`: a callable that receives the started :class:`Launcher`
(its ``session``, ``endpoint``, ``run_folder``) and runs in the main thread until the user quits; without
one the supervisor blocks until Ctrl-C, SIGTERM (``kinema down``) or a child dies. A crashed agent
(a behavior's ``os._exit``, a segfault in C code) is started again, up to :data:`AGENT_RESTARTS` times,
each said on the terminal and in the supervisor's log; the drivers stop the goals it left running.
"""

from __future__ import annotations

import importlib.util
import logging
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinema.errors import KinemaError, TransportError
from kinema.process.lifeline import Lifeline
from kinema.process.stop import TERMINATE, StopRequest
from kinema.runtime.cell import CellError
from kinema.runtime.cell_claim import CellClaim
from kinema.runtime.instance import InstanceRecord
from kinema.runtime.run_folder import RunFolder, prune_runs

if TYPE_CHECKING:
    from kinema.transport import Session

log = logging.getLogger("kinema.supervisor")

READY_TIMEOUT_S = 120.0
STOP_GRACE_S = 5.0
VIEWER_READY_TIMEOUT_S = 30.0
# A crashed agent is started again this many times per `kinema run` (the drivers hold the robot still
# meanwhile: they stop the goals of an agent that went away); after that the run stops.
AGENT_RESTARTS = 3
# How long a `kinema run` that finds the cell's roles claimed on this machine waits for the claiming one's
# agent or drivers to show on the network (so that it refuses with what runs there).
CLAIM_WAIT_S = 60.0


@dataclass
class LaunchOptions:
    """What ``kinema run`` starts.

    Attributes:
        config: the config package name.
        workspace: the workspace root (None: only bundled packages).
        agent: start the agent (False with ``-o/--only-drivers``).
        drivers: start the config's drivers (False with ``-n/--no-drivers``).
        endpoint: the router endpoint to host or join (None: ``KINEMA_ZENOH_CONNECT`` or 7447).
        verbose: DEBUG logs, echoed to the terminal.
        tick_rate_hz: the agent's tick rate.
        sim_speed: for simulated drivers, ``"1"`` (real time), a factor such as ``"4"``, or ``"max"``
            (None: the driver's default, real time).
        ui: runs in the main thread once everything started (the TUI); returns an exit code.
        viewer: also start the 3D view (``python -m kinema.viz``, the process behind ``kinema view``).
        groot2_port: the agent serves the Groot2 protocol on 127.0.0.1 at this port and the next
            (None: off).
        record: the agent records every objective run as a ``.btlog`` file in the run folder's
            ``recordings/``.
        echo: print progress lines (the CLI); tests turn it off.
        insecure: allow a plain-text listener beyond loopback (with a warning).
        security_dir: the folder of ``kinema security init`` for ``tls/`` endpoints (None: the default).
    """

    config: str
    workspace: Path | None = None
    agent: bool = True
    drivers: bool = True
    endpoint: str | None = None
    verbose: bool = False
    tick_rate_hz: float = 100.0
    sim_speed: str | None = None
    ui: Callable[[Launcher], int] | None = None
    viewer: bool = False
    groot2_port: int | None = None
    record: bool = True
    echo: Callable[[str], None] = field(default=print)
    insecure: bool = False
    security_dir: Path | None = None


@dataclass
class Child:
    """A process the supervisor started."""

    name: str
    process: subprocess.Popen[bytes]
    log_file: Path
    # A child whose exit stops the instance (the 3D view is not: closing it leaves the runtime running).
    essential: bool = True


def _die_with_parent() -> None:
    """In the child, before exec: get SIGTERM when the supervisor dies (Linux; a no-op elsewhere)."""
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        pr_set_pdeathsig = 1
        libc.prctl(pr_set_pdeathsig, signal.SIGTERM)
    except OSError:
        pass


class Launcher:
    """Starts and supervises one Kinema instance (see the module docstring)."""

    def __init__(self, options: LaunchOptions) -> None:
        self.options = options
        self.session: Session | None = None
        self.endpoint = ""
        self.hosting = False
        self.run_folder: RunFolder | None = None
        self.children: list[Child] = []
        self.record: InstanceRecord | None = None
        self.lifeline: Lifeline | None = None
        self._stop = StopRequest()
        self._echo_stop = threading.Event()
        self._config: Any = None
        self._clock = "auto"
        self.agent_restarts = 0
        self._claim = CellClaim()

    # -- start --------------------------------------------------------------------------------------

    def start(self) -> None:
        """Start the router, the drivers and the agent; returns when objectives can be started.

        Raises:
            KinemaError: the router cannot be hosted or joined, or the agent failed to start (the message
                carries the end of its log).
        """
        from kinema.process.log_files import configure_process_logging

        options = self.options
        # A config that does not resolve is refused before anything exists: no run folder, no router.
        self._resolved()
        self.run_folder = RunFolder.create(options.config, keep=None)  # pruned once the cell is ours
        supervisor_log = self.run_folder.log_file("supervisor")
        configure_process_logging(supervisor_log, verbose=options.verbose, echo=options.verbose)
        for warning in self._resolved().warnings:  # a key no schema knows: a typo, most of the time
            log.warning("%s", warning)
            options.echo(f"warning: {warning}")
        self.lifeline = Lifeline()
        try:
            self.session = self._open_router()
            self.hosting = self.session.is_router
            log.info("%s the router at %s", "hosting" if self.hosting else "joined", self.endpoint)
            self.record = InstanceRecord(
                os.getpid(),
                self.endpoint,
                str(self.run_folder.path),
                options.config,
                str(options.workspace or ""),
            )
            self.record.save()
            prune_runs()
            clock = "auto"
            starting = self._start_drivers() if options.drivers else []
            if options.drivers and not starting:
                clock = "wall"  # no simulator will publish /clock: time must not freeze
            self._clock = clock
            if options.agent:
                starting.append(self._start_agent(clock))
            for child, stream in starting:
                self._await_ready(child, stream)
                if child.name != "agent":
                    self.options.echo(f"driver {child.name!r} is running")
                elif options.groot2_port is not None:
                    self.options.echo(f"Groot2: connect to 127.0.0.1 port {options.groot2_port}")
            if options.viewer:
                self._start_viewer()
        except KinemaError as error:
            # Refused before anything ran (another run holds the cell, a listener it may not open, no
            # router to join): the terminal has the reason, and the empty run must not become `kinema
            # logs`' newest. A run whose driver or agent did not start keeps its folder: the message
            # points into it.
            refused = isinstance(error, CellError) or self.session is None
            self.stop()
            if refused:
                self.run_folder.discard()
            raise
        except BaseException:
            self.stop()
            raise

    def _resolved(self) -> Any:
        """The resolved config package (resolved once per launcher)."""
        if self._config is None:
            from kinema.config import Workspace, resolve_config

            workspace = Workspace.discover(self.options.workspace) if self.options.workspace else None
            self._config = resolve_config(self.options.config, workspace)
        return self._config

    def _start_drivers(self) -> list[tuple[Child, Any]]:
        """Spawn the drivers the config wants; returns each with the read end of its ready pipe."""
        from kinema.drivers.registry import drivers_for_config

        specs = drivers_for_config(self._resolved())
        if not specs:
            self.options.echo(f"config {self.options.config!r} needs no driver")
            return []
        started = []
        for spec in specs:
            if not _runnable_module(spec.module):
                self.options.echo(
                    f"driver {spec.name!r} ({spec.description}) is not available yet: not started"
                )
                log.warning("driver %s: module %s has no __main__; not started", spec.name, spec.module)
                continue
            assert self.run_folder is not None
            log_file = self.run_folder.log_file(spec.name)
            argv = spec.command(
                config=self.options.config,
                connect=self.endpoint,
                workspace=self.options.workspace,
                sim_speed=self.options.sim_speed,
                log_file=log_file,
                verbose=self.options.verbose,
            )
            started.append(self._spawn_with_ready(spec.name, argv, log_file))
        return started

    def _start_agent(self, clock: str) -> tuple[Child, Any]:
        assert self.run_folder is not None
        log_file = self.run_folder.log_file("agent")
        argv = [
            sys.executable,
            "-m",
            "kinema.runtime.agent_process",
            "--config",
            self.options.config,
            "--connect",
            self.endpoint,
            "--log-file",
            str(log_file),
            "--tick-rate",
            str(self.options.tick_rate_hz),
            "--clock",
            clock,
        ]
        if self.options.workspace is not None:
            argv += ["--workspace", str(self.options.workspace)]
        if self.options.verbose:
            argv.append("--verbose")
        if self.options.record:
            from kinema.runtime.recordings import FOLDER_NAME

            argv += ["--recordings", str(self.run_folder.path / FOLDER_NAME)]
        if self.options.groot2_port is not None:
            argv += ["--groot2-port", str(self.options.groot2_port)]
        return self._spawn_with_ready("agent", argv, log_file)

    def _spawn_with_ready(self, name: str, argv: list[str], log_file: Path) -> tuple[Child, Any]:
        """Spawn a child that writes ``ready`` to ``--ready-fd`` once it serves."""
        read_fd, write_fd = os.pipe()
        try:
            child = self._spawn(name, [*argv, "--ready-fd", str(write_fd)], log_file, pass_fds=(write_fd,))
        except BaseException:
            os.close(read_fd)
            raise
        finally:
            os.close(write_fd)
        return child, os.fdopen(read_fd, "r")

    def _await_ready(self, child: Child, stream: Any) -> None:
        """Wait for a child's ``ready`` line (the agent and the drivers start in parallel)."""
        with stream:
            if _wait_ready(stream, child.process, READY_TIMEOUT_S, self._stop):
                log.info("%s is ready", child.name)
                return
        if self._stop.is_set():
            raise KinemaError(f"interrupted ({self._stop.reason}) while {child.name} was starting")
        tail = _tail(child.log_file, 8)
        raise KinemaError(
            f"{child.name} did not start (exit code {child.process.poll()}); end of {child.log_file}:\n{tail}"
        )

    def _start_viewer(self) -> None:
        """Start the 3D view and echo its URL; a view that cannot start is reported, not fatal."""
        assert self.run_folder is not None
        log_file = self.run_folder.log_file("viewer")
        read_fd, write_fd = os.pipe()
        argv = [sys.executable, "-m", "kinema.viz", "--connect", self.endpoint]
        argv += ["--config", self.options.config, "--log-file", str(log_file), "--ready-fd", str(write_fd)]
        if self.options.workspace is not None:
            argv += ["--workspace", str(self.options.workspace)]
        try:
            child = self._spawn("viewer", argv, log_file, pass_fds=(write_fd,), essential=False)
        finally:
            os.close(write_fd)
        with os.fdopen(read_fd, "r") as ready:
            line = _read_line(ready, child.process, VIEWER_READY_TIMEOUT_S, self._stop)
        if line and not line.startswith("error:"):
            self.options.echo(f"3D view: {line} (`kinema view` opens another)")
        else:
            self.options.echo(f"the 3D view did not start ({line or 'no answer'}); see {log_file}")

    def _spawn(
        self,
        name: str,
        argv: list[str],
        log_file: Path,
        pass_fds: tuple[int, ...] = (),
        *,
        essential: bool = True,
    ) -> Child:
        log.info("starting %s: %s", name, " ".join(argv))
        env = os.environ.copy()
        if self.options.security_dir is not None:
            # The agent's file rule refuses this folder too (kinema.behaviors.file_access).
            env["KINEMA_SECURITY_DIR"] = str(self.options.security_dir)
        if self.lifeline is not None:
            env.update(self.lifeline.child_env())
            pass_fds = (*pass_fds, self.lifeline.read_fd)
        with open(log_file, "ab") as output:
            process = subprocess.Popen(
                argv,
                stdin=subprocess.DEVNULL,
                stdout=output,
                stderr=subprocess.STDOUT,
                env=env,
                pass_fds=pass_fds,
                preexec_fn=_die_with_parent if sys.platform.startswith("linux") else None,
            )
        child = Child(name, process, log_file, essential)
        self.children.append(child)
        if self.record is not None:
            self.record.children.append(process.pid)
            self.record.save()
        return child

    # -- run and stop -----------------------------------------------------------------------------------

    def request_stop(self, reason: str = "") -> None:
        """Ask :meth:`wait` to return (the TUI calls this when it closes; SIGTERM and Ctrl-C do the same)."""
        self._stop.set(reason)

    def wait(self) -> int:
        """Block until a stop is requested or a child exits; return the exit code for the CLI."""
        while not self._stop.wait(0.2):
            for child in list(self.children):
                code = child.process.poll()
                if code is not None and not child.essential:
                    log.warning("%s exited (code %s); the runtime keeps running", child.name, code)
                    self.children.remove(child)
                    continue
                if code is not None and child.name == "agent" and self.agent_restarts < AGENT_RESTARTS:
                    if self._restart_agent(child, code):
                        continue
                    return 1
                if code is not None:
                    gave_up = (
                        f" after {AGENT_RESTARTS} restarts"
                        if child.name == "agent" and self.agent_restarts >= AGENT_RESTARTS > 0
                        else ""
                    )
                    message = (
                        f"{child.name} exited unexpectedly (code {code}){gave_up}; see {child.log_file}; "
                        "stopping the runtime"
                    )
                    log.error("%s", message)
                    self.options.echo(message)
                    return 1
        log.info("stopping (%s)", self._stop.reason or "requested")
        return 0

    def _restart_agent(self, crashed: Child, code: int) -> bool:
        """Start the agent again after it exited unexpectedly; False when the new one did not start."""
        self.agent_restarts += 1
        message = (
            f"agent exited unexpectedly (code {code}); see {crashed.log_file}; restarting it "
            f"({self.agent_restarts} of {AGENT_RESTARTS}); the drivers hold the robot still meanwhile"
        )
        log.error("%s", message)
        self.options.echo(message)
        self.children.remove(crashed)
        if self.record is not None and crashed.process.pid in self.record.children:
            self.record.children.remove(crashed.process.pid)
            self.record.save()
        try:
            child, stream = self._start_agent(self._clock)
            self._await_ready(child, stream)
        except KinemaError as error:
            log.error("the agent did not start again: %s", error)
            self.options.echo(f"the agent did not start again: {error}; stopping")
            return False
        log.info("agent restarted (pid %d)", child.process.pid)
        self.options.echo(f"agent restarted (pid {child.process.pid}); objectives can be started")
        return True

    def stop(self) -> None:
        """Stop the children (SIGTERM, SIGKILL after a grace period), close the router, drop the record."""
        self._echo_stop.set()
        for child in reversed(self.children):
            if child.process.poll() is None:
                child.process.terminate()
        deadline = time.monotonic() + STOP_GRACE_S
        for child in reversed(self.children):
            try:
                child.process.wait(max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                log.warning("%s did not stop within %.0f s; killing it", child.name, STOP_GRACE_S)
                child.process.kill()
                child.process.wait(2.0)
        self.children.clear()
        if self.lifeline is not None:
            self.lifeline.close()
            self.lifeline = None
        if self.session is not None:
            self.session.close()
            self.session = None
        if self.record is not None:
            self.record.remove()
            self.record = None
        self._claim.release()

    def run(self) -> int:
        """Start, block (or run the UI), stop; SIGINT and SIGTERM stop cleanly. Returns the exit code."""
        with self._stop.handle_signals(TERMINATE):
            ready = False
            try:
                self.start()
                assert self.run_folder is not None
                role = "hosting the router" if self.hosting else "joined the router"
                what = (
                    "objectives can be started"
                    if self.options.agent
                    else "drivers only; objectives run by an agent elsewhere"
                )
                self.options.echo(
                    f"Kinema is running: {what} (config {self.options.config}, {role} at "
                    f"{self.endpoint}, logs in {self.run_folder.path}). Stop with Ctrl-C or `kinema down`."
                )
                ready = True
                self._watch_cell()
                if self.options.ui is not None:
                    return self.options.ui(self)
                self._echo_plugin_reports()
                return self.wait()
            finally:
                self.stop()
                if ready:
                    # The last line in the terminal: after the UI's screen is gone, the ready line above would
                    # otherwise read as if the runtime were still up.
                    self.options.echo(f"Kinema stopped (config {self.options.config}).")

    def _open_router(self) -> Session:
        """Host (or join) the router as planned from ``--connect``; say what listens beyond loopback."""
        from kinema.runtime.router_plan import open_router, plan_router
        from kinema.transport.exposure import insecure_warning
        from kinema.transport.heap import bound_heap_growth

        bound_heap_growth()  # the router reassembles large messages too; see kinema.transport.heap
        plan = plan_router(self.options.endpoint, self.options.security_dir)
        self._claim_cell(plan.local)
        session = open_router(plan, insecure=self.options.insecure, before_join=self._check_cell_is_free)
        self.endpoint = plan.local
        if session.exposed:
            log.warning("%s", insecure_warning(session.exposed))
            self.options.echo(insecure_warning(session.exposed))
        if plan.config_file is not None and session.is_router:
            remote = [endpoint for endpoint in plan.listen if endpoint != plan.local]
            self.options.echo(
                f"other machines join at {', '.join(remote)} with a client certificate from "
                f"{plan.config_file.parent} (mutual TLS, access rules of {plan.config_file})"
            )
        return session

    def _claim_cell(self, endpoint: str) -> None:
        """Take this machine's claim on the roles this run starts (see kinema.runtime.cell_claim).

        Raises:
            CellError: another `kinema run` holds one: the usual message once its members show on the
                network, else one naming the process that holds the claim.
        """
        from kinema.runtime.cell_claim import AGENT, DRIVERS
        from kinema.transport import resolve_domain_id

        roles = [
            role for role, wanted in ((AGENT, self.options.agent), (DRIVERS, self.options.drivers)) if wanted
        ]
        domain = resolve_domain_id(None)
        holder = self._claim.take(endpoint, domain, roles)
        if holder is None:
            return
        log.info("the cell at %s is claimed on this machine by pid %s; looking at it", endpoint, holder)
        deadline = time.monotonic() + CLAIM_WAIT_S
        while time.monotonic() < deadline and not self._stop.is_set():
            self._check_cell_is_free(endpoint)  # raises the usual CellError once its members show
            holder = self._claim.take(endpoint, domain, roles)
            if holder is None:
                return  # the other one gave up (or stopped) meanwhile
            time.sleep(0.2)
        raise CellError(
            f"another kinema run (pid {holder}) is starting the {' and '.join(roles)} of the cell at "
            f"{endpoint} on this machine, so nothing was started.\n  stop it: `kinema down`, or Ctrl-C in "
            "its terminal\n  run a second cell beside it: `kinema run --connect tcp/127.0.0.1:<another port>`"
        )

    def _check_cell_is_free(self, endpoint: str) -> None:
        """Refuse to start a second agent or second drivers on the router at ``endpoint`` that has them
        (one per cell); called before joining it, so that a refused run joins nothing.
        """
        from kinema.runtime.cell import check_cell_is_free
        from kinema.transport import open_session

        # Looked at as a client: see check_cell_is_free on why a peer that just joined would miss some.
        try:
            looking = open_session(endpoint, mode="client")
        except TransportError:
            return  # nothing answers there: joining fails too, and says why
        with looking:
            check_cell_is_free(
                looking, agent=self.options.agent, drivers=self.options.drivers, endpoint=endpoint
            )

    def _watch_cell(self) -> None:
        """Report two agents or two drivers on the network, should they appear anyway."""
        from kinema.runtime.cell import CellWatch

        assert self.session is not None

        def report(message: str) -> None:
            log.error("%s", message)
            if self.options.ui is None:
                self.options.echo(f"warning: {message}")

        CellWatch(self.session, report)  # closed with the session

    def _echo_plugin_reports(self) -> None:
        """Print the agent's plugin load errors, hot-reload outcomes and watchdog reports here as they are
        logged.

        Without a UI this terminal is where the user looks; the log file (``kinema logs``) has them too.
        """
        from kinema.process.log_files import PLUGIN_LOGGER, follow_entries

        assert self.run_folder is not None
        entries = follow_entries(self.run_folder.path, stop=self._echo_stop, from_start=True)
        marker = f"[{PLUGIN_LOGGER}] "
        # The watchdog's reports (behavior code stuck in a call) too: runtime.md promises them here.
        watchdog = "[kinema.objective_server] watchdog: "

        def echo() -> None:
            for entry in entries:
                rest = entry.text.partition(marker)[2]
                if not rest and watchdog in entry.text:
                    rest = "watchdog: " + entry.text.partition(watchdog)[2]
                if rest:
                    self.options.echo(f"{entry.process}: {entry.level.lower()}: {rest}")

        threading.Thread(target=echo, name="kinema-plugin-echo", daemon=True).start()


def _runnable_module(module: str) -> bool:
    """True when ``python -m module`` would run (the package exists and has a ``__main__``)."""
    try:
        return importlib.util.find_spec(f"{module}.__main__") is not None
    except ModuleNotFoundError:
        return False


def _wait_ready(stream: Any, process: subprocess.Popen[bytes], timeout: float, stop: StopRequest) -> bool:
    """Wait for the child's ``ready`` line; False when it exits, times out or a stop is requested."""
    import select

    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and not stop.is_set():
        readable, _, _ = select.select([stream], [], [], 0.1)
        if readable:
            return stream.readline().strip() == "ready"
        if process.poll() is not None:
            return False
    return False


def _read_line(stream: Any, process: subprocess.Popen[bytes], timeout: float, stop: StopRequest) -> str:
    """The child's first line on ``stream`` ("" when it exits, times out or a stop is requested)."""
    import select

    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and not stop.is_set():
        readable, _, _ = select.select([stream], [], [], 0.1)
        if readable:
            return str(stream.readline()).strip()
        if process.poll() is not None:
            return ""
    return ""


def _tail(path: Path, lines: int) -> str:
    try:
        return "\n".join(path.read_text(encoding="utf-8", errors="replace").splitlines()[-lines:])
    except OSError:
        return "(no log)"
