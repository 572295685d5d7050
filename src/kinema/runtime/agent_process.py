"""The agent as a process: ``python -m kinema.runtime.agent_process --config lab_sim ...``.

``kinema run`` starts it as a child (so the tick thread never competes with the supervisor or a UI for
the GIL, and a crash in a behavior cannot take the router down); tests start it with ``--objectives``
folders and ``--host-router`` on a free port so they need no config package and no other process.
It prints nothing on stdout; with ``--ready-fd N`` it writes ``ready`` to that file descriptor once
every service is declared, which is how the supervisor knows objectives can be started.
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from kinema.errors import KinemaError
from kinema.process.stop import TERMINATE, StopRequest

if TYPE_CHECKING:
    from kinema.behaviors.context import BehaviorContext
    from kinema.runtime.agent import Agent
    from kinema.transport import Session

log = logging.getLogger("kinema.agent")

ClockChoice = Literal["auto", "wall", "sim"]


@dataclass
class AgentOptions:
    """How to build an agent.

    Attributes:
        config: the config package (None: no config, only ``objective_dirs`` and built-in nodes).
        workspace: the workspace to resolve ``config`` in (None: the active one).
        objective_dirs: extra objective folders (added after the config's libraries).
        tick_rate_hz: ticks per second.
        clock: ``sim`` follows ``/clock``; ``wall`` is wall time; ``auto`` picks sim when the config has
            a simulator.
        hot_reload: watch behavior packages and objective folders.
        waypoints_file: the waypoints file to serve instead of the config's.
        groot2_port: serve the Groot2 protocol on 127.0.0.1 at this port and the next (None: off).
        recordings_dir: write a ``.btlog`` recording of every run there (None: no recordings).
    """

    config: str | None = None
    workspace: Path | None = None
    objective_dirs: list[Path] = field(default_factory=list)
    tick_rate_hz: float = 100.0
    clock: ClockChoice = "auto"
    hot_reload: bool = True
    waypoints_file: Path | None = None
    groot2_port: int | None = None
    recordings_dir: Path | None = None


def build_agent(options: AgentOptions, session: Session) -> Agent:
    """Resolve the config, load behaviors and objectives, and return an :class:`Agent` (not started)."""
    from kinema.behaviors.context import BehaviorContext
    from kinema.behaviors.logger import LogSink
    from kinema.bt import WallClock
    from kinema.drivers.mujoco import names as driver_names
    from kinema.runtime import names
    from kinema.runtime.agent import Agent, build_host
    from kinema.runtime.objective_server import ObjectiveServer
    from kinema.runtime.objective_source import LibraryTreeSource, library_from_folders
    from kinema.runtime.sim_clock import SimClock
    from kinema.transport import Node

    resolved = None
    if options.config:
        from kinema.config import Workspace, resolve_config

        workspace = Workspace.discover(options.workspace) if options.workspace else None
        resolved = resolve_config(options.config, workspace)
    use_sim = options.clock == "sim" or (
        options.clock == "auto" and resolved is not None and resolved.mujoco_model_path is not None
    )
    clock: Any = SimClock() if use_sim else WallClock()
    node = Node(session, names.NODE_NAME)
    if use_sim:
        node.create_subscription(driver_names.CLOCK_TYPE, driver_names.CLOCK_TOPIC, clock.on_clock_message)
        log.info("time follows %s (simulation time)", driver_names.CLOCK_TOPIC)
        _warn_without_clock(clock)
    sink = LogSink()
    context = BehaviorContext(
        node, clock=clock, log_sink=sink, robot_model=_robot_model_provider(resolved), config=resolved
    )
    from kinema.runtime.planning_scene_service import serve_planning_scene

    serve_planning_scene(node, context)  # as move_group serves it, from the scene the behaviors plan in
    host = build_host(resolved) if resolved is not None else None
    extra = [Path(folder) for folder in options.objective_dirs]

    def load_library() -> Any:
        from kinema.config import LibraryPath, ObjectiveLibrary

        if resolved is None:
            return library_from_folders(extra)
        paths = list(resolved.objective_library_paths)
        paths += [
            LibraryPath(f"extra{i}", folder, resolved.name, resolved.name) for i, folder in enumerate(extra)
        ]
        library = ObjectiveLibrary.from_libraries(paths, resolved.chain)
        library.resolved = resolved
        return library

    source = LibraryTreeSource(load_library, host=host, context=context, clock=clock)
    source.factory()  # load now: errors show at start, and the first objective starts fast
    if resolved is not None:
        threading.Thread(
            target=_load_planning, args=(context,), name="kinema-planning-load", daemon=True
        ).start()
    waypoints = _waypoint_store(options, resolved)
    server = ObjectiveServer(source, tick_rate_hz=options.tick_rate_hz)
    group = resolved.get("moveit_params.joint_group_name") if resolved is not None else None
    agent = Agent(
        session,
        server,
        source=source,
        waypoints=waypoints,
        log_sink=sink,
        clock=clock,
        node=node,
        waypoint_groups=[str(group)] if group else [],
        robot_groups=lambda: _robot_groups(context),
    )
    _add_debugging_doors(agent, options)
    if host is not None:
        host.subscribe(agent.on_reload_event)
        if options.hot_reload:
            folders = [p.path for p in resolved.objective_library_paths] if resolved is not None else []
            watcher = host.watch([*folders, *extra])
            if resolved is not None:
                _watch_config_files(watcher, resolved, agent)
    elif options.hot_reload and extra:
        from kinema.plugins import BehaviorHost

        watcher_host = BehaviorHost([])
        watcher_host.subscribe(agent.on_reload_event)
        watcher_host.watch(extra)
    return agent


def _waypoint_store(options: AgentOptions, resolved: Any) -> Any:
    """The waypoints the agent serves (see :mod:`kinema.config.waypoint_location`), tidied at start."""
    from kinema.config import WaypointStore
    from kinema.config.waypoint_location import waypoint_store_for

    store: WaypointStore | None
    if options.waypoints_file is not None:
        store = WaypointStore(options.waypoints_file)
    elif resolved is not None:
        store = waypoint_store_for(resolved)
    else:
        return None
    if store is None:
        return None
    for stray in store.remove_stray_temporaries():
        log.warning("removed %s, left by a save that was interrupted", stray)
    if store.notice:
        log.info("waypoints: %s", store.notice)
    return store


def _warn_without_clock(clock: Any, after_s: float = 10.0) -> None:
    """Say so in the log when no simulator publishes time: Sleep and Timeout would wait forever."""
    from kinema.drivers.mujoco.names import CLOCK_TOPIC

    def check() -> None:
        if not clock.wait_until_running(after_s):
            log.warning(
                "no %s message after %.0f s: simulation time stands still, so Sleep/Timeout nodes wait "
                "until a simulator runs (start its driver, or run the agent with --clock wall)",
                CLOCK_TOPIC,
                after_s,
            )

    threading.Thread(target=check, name="kinema-clock-watch", daemon=True).start()


def _watch_config_files(watcher: Any, resolved: Any, agent: Agent) -> None:
    """Say, when a YAML file of a chain package's config folder changes (its config.yaml, MoveIt Pro's
    ros2_control and MoveIt parameter files), that the running runtime keeps the config it started with:
    objective files reload, the robot's settings need a restart. A user who edited robot.gripper or
    robot.tool_frame and ran again saw the old values at work and nothing saying why."""

    def changed(folder: Path, paths: tuple[Path, ...], _first: float) -> None:
        names = ", ".join(sorted({str(path) for path in paths}))
        if not names:
            return
        text = (
            f"{names} changed: this runtime keeps the config it started with; restart it (`kinema down`, "
            f"then `kinema run -c {resolved.name}`) to use the change"
        )
        agent.warn_reload(text)
        if agent.source is not None:
            # An objective the edit added (a new behavior package's library) is refused as unknown until
            # then: the refusal says why.
            agent.source.restart_note = text

    for package in resolved.chain_packages:
        folder = Path(package.config_file).parent
        if folder.is_dir():
            watcher.add(folder, (".yaml",), changed)


def _robot_groups(context: BehaviorContext) -> list[str]:
    """The robot's planning groups (none known when its model does not load: nothing is refused then)."""
    try:
        model = context.robot_model
    except KinemaError:
        return []
    return sorted(model.groups) if model is not None else []


def _load_planning(context: BehaviorContext) -> None:
    """Build the robot model, its collision geometry and the planning scene now, beside the tick thread:
    the first plan of a robot with mesh collision shapes otherwise waits for them (an SO-ARM's 34 STL
    meshes: 3-4 s). A failure is the first planning behavior's to report (it says what to fix)."""
    started = time.monotonic()
    try:
        model = context.robot_model
        if model is not None:
            model.collision_geometry()
            context.planning_scene  # noqa: B018 - made on first use
    except Exception as error:
        log.debug("loading the planning resources early failed: %s", error)
        return
    log.info("robot model and collision shapes loaded (%.1f s)", time.monotonic() - started)


def _robot_model_provider(resolved: Any) -> Any:
    if resolved is None:
        return None

    def load() -> Any:
        from kinema.config.robot_description import package_index, planning_urdf
        from kinema.motion.robot_model import RobotModel

        return RobotModel.from_urdf(
            planning_urdf(resolved, check_meshes=False),
            resolved.srdf_path,
            resolved.joint_limits_path,
            package_dirs=package_index(resolved).package_dirs(),
        )

    return load


def _add_debugging_doors(agent: Agent, options: AgentOptions) -> None:
    """Recordings and Groot2: tree listeners of the objective server, closed with the agent."""
    if options.recordings_dir is not None:
        from kinema.runtime.recordings import RunRecorder

        recorder = RunRecorder(options.recordings_dir)
        agent.server.add_listener(recorder)
        agent.on_close.append(recorder.close)
        log.info("recording every objective run into %s", options.recordings_dir)
    if options.groot2_port is not None:
        from kinema.runtime.groot2 import Groot2Server

        groot2 = Groot2Server(options.groot2_port)
        agent.server.add_listener(groot2)
        agent.on_close.append(groot2.close)
        log.info("Groot2 can attach at 127.0.0.1:%d", options.groot2_port)


#: zenoh's pool for sending large messages through shared memory (its default is 16 MiB, all of it
#: resident in the agent once some trajectories went through it). The agent's large messages
#: (trajectories, node tables, blackboard snapshots) are tens to hundreds of kB; a larger one than the
#: pool is sent the ordinary way.
SHARED_MEMORY_POOL_BYTES = 4 << 20


def _shared_memory_pool() -> dict[str, Any]:
    """The agent's zenoh overrides: a smaller shared-memory pool, unless a zenoh config file is used
    (``KINEMA_ZENOH_CONFIG``: what it says stands)."""
    from kinema.transport.session import ENV_CONFIG

    if os.environ.get(ENV_CONFIG):
        return {}
    return {"transport/shared_memory/transport_optimization/pool_size": SHARED_MEMORY_POOL_BYTES}


class _TrimHeapAfterRuns:
    """Gives the heap's free pages back after each objective run (:func:`kinema.transport.heap.trim_soon`).

    A run's behaviors, result waiters and transport queries allocate on many short-lived threads, and
    glibc spreads them over up to 8 arenas per core; what they free stays resident as scattered free
    chunks, which grew the agent by about 5-10 kB per start/cancel cycle (``benchmarks/soak.py``). A
    trim a second after each run (in the background, about a millisecond) returns those pages.
    """

    def on_status(self, status: Any, objective_name: str) -> None:
        pass

    def on_node_status(self, objective_name: str, changes: Any) -> None:
        pass

    def on_blackboard(self, objective_name: str, entries: Any) -> None:
        pass

    def on_run_finished(self, run: Any, result: Any) -> None:
        from kinema.transport.heap import trim_soon

        trim_soon()


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m kinema.runtime.agent_process", description=__doc__)
    parser.add_argument("--config", "-c", help="config package to run")
    parser.add_argument("--workspace", "-w", type=Path, help="workspace to resolve the config in")
    parser.add_argument("--objectives", action="append", type=Path, default=[], help="extra objective folder")
    parser.add_argument("--connect", help="router endpoint to join (default KINEMA_ZENOH_CONNECT or 7447)")
    parser.add_argument(
        "--host-router", metavar="ENDPOINT", help="host the router here instead of joining one"
    )
    parser.add_argument("--tick-rate", type=float, default=100.0, help="ticks per second (default 100)")
    parser.add_argument("--clock", choices=("auto", "wall", "sim"), default="auto", help="time source")
    parser.add_argument("--no-hot-reload", action="store_true", help="do not watch files")
    parser.add_argument("--waypoints", type=Path, help="waypoints file to serve (default: the config's)")
    parser.add_argument("--log-file", type=Path, help="write the log there (run format)")
    parser.add_argument("--groot2-port", type=int, help="serve Groot2 on 127.0.0.1 at this port and the next")
    parser.add_argument("--recordings", type=Path, help="record every run (.btlog) in this folder")
    parser.add_argument("--ready-fd", type=int, help="write 'ready' to this file descriptor when serving")
    parser.add_argument("--verbose", "-v", action="store_true", help="log at DEBUG level")
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the agent until SIGTERM/SIGINT; exit 1 with one line on stderr when it cannot start."""
    from kinema.process import lifeline
    from kinema.process.log_files import configure_process_logging

    args = _parser().parse_args(argv)
    configure_process_logging(args.log_file, verbose=args.verbose)
    from kinema.process import memory_probe

    memory_probe.install_from_environment()  # KINEMA_DEBUG_MEMORY: SIGUSR2 logs a memory report
    from kinema.mujoco_gl import no_rendering

    no_rendering()  # it reads MuJoCo scenes (planning scene, camera frames) but never renders
    with StopRequest().handle_signals(TERMINATE) as stop:
        lifeline.hold()
        return _serve(args, stop)


def _serve(args: argparse.Namespace, stop: StopRequest) -> int:
    """Build the agent, serve until ``stop``, close it; exit 1 with one line on stderr if it cannot start."""
    # Before zenoh's threads start: a refused 50 MB request must not stay resident in their heaps.
    from kinema.transport.heap import bound_heap_growth

    bound_heap_growth()
    options = AgentOptions(
        config=args.config,
        workspace=args.workspace,
        objective_dirs=args.objectives,
        tick_rate_hz=args.tick_rate,
        clock=args.clock,
        hot_reload=not args.no_hot_reload,
        waypoints_file=args.waypoints,
        groot2_port=args.groot2_port,
        recordings_dir=args.recordings,
    )
    try:
        from kinema.transport import host_router, open_session

        session = (
            host_router(args.host_router)
            if args.host_router
            else open_session(args.connect, config_overrides=_shared_memory_pool())
        )
    except KinemaError as error:
        log.error("%s", error)
        print(f"error: {error}", file=sys.stderr)
        return 1
    from kinema.runtime.cell import CellWatch
    from kinema.transport.presence import AGENT, declare_presence

    # Announced before its nodes exist, so whoever sees them also knows whose they are.
    declare_presence(
        session, AGENT, config=options.config or "", endpoint=args.connect or args.host_router or ""
    )
    try:
        agent = build_agent(options, session)
        agent.server.add_listener(_TrimHeapAfterRuns())
        agent.start()
    except KinemaError as error:
        log.error("%s", error)
        print(f"error: {error}", file=sys.stderr)
        session.close()
        return 1
    CellWatch(session, agent.report_cell_conflict)  # reports another agent; closed with the session
    log.info("agent serving (config %s, pid %d)", options.config or "-", os.getpid())
    if args.ready_fd is not None:
        with os.fdopen(args.ready_fd, "w") as ready:
            ready.write("ready\n")
    try:
        stop.wait()  # a signal's stop is noticed within kinema.process.stop.POLL_S
    finally:
        log.info("agent stopping")
        agent.close()
        session.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
