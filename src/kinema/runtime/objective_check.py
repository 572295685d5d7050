"""Check a folder of objectives against a config: how many validate, and how many runnable ones succeed.

What ``kinema objective check`` does, usable from a test or a program:

1. :class:`CheckWorkspace` copies the folder (and any folders its SubTrees reach) into a package of a
   temporary workspace that is *based on* the chosen config, so the folder's objectives see that config's
   behaviors, core subtrees, waypoints, robot and simulation, shadow its objectives of the same ID, and
   read and write their own files (a YAML trajectory beside them) in the copy, never in the original.
   The user's workspace packages stay visible through links.
2. :meth:`CheckWorkspace.validate` validates every XML file of the folder with its SubTree closure
   against the config's behaviors (what ``kinema objective list`` reports), one verdict per file.
3. :class:`CheckCell` starts the config's simulation and the agent headless at maximum sim speed, with
   approvals granted automatically (as ``kinema run --auto-approve``); :meth:`CheckCell.run` resets the
   cell (the folder's files as shipped, the simulation to its start keyframe, the controllers to those
   active at startup, the objects objectives added to the planning scene removed) and runs one
   objective until it ends or has run ``time_limit`` seconds of simulated time (and at least
   :data:`MIN_WALL_S` wall seconds). An objective still running then without having failed (a loop such
   as "3 Waypoints Pick and Place") is cancelled and counts as running correctly: "kept running".

Runnable objectives that do not validate count as not succeeding, with their validation problem.
"""

from __future__ import annotations

import logging
import os
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import yaml

from kinema.errors import ConfigError, KinemaError, TransportError

if TYPE_CHECKING:
    from kinema.config import ObjectiveLibrary, ResolvedConfig
    from kinema.runtime.launcher import Launcher
    from kinema.sdk import ObjectiveClient
    from kinema.transport import Node

log = logging.getLogger(__name__)

#: The package the checked folder is copied into (based on the config checked against).
CHECK_PACKAGE = "kinema_objective_check"
#: The package the folders its SubTrees reach are copied into (between the config and the check package).
SUBTREES_PACKAGE = "kinema_objective_check_subtrees"
#: Simulated seconds an objective may run before it is cancelled (and counts as "kept running").
DEFAULT_TIME_LIMIT_S = 120.0
#: Wall-clock seconds an objective runs at least before the time limit cancels it: at maximum sim speed
#: simulated time outruns what waits on the computer (rendering a camera, planning, registration).
MIN_WALL_S = 30.0
#: Wall-clock seconds an objective may take at most, whatever its sim time (a stalled simulation).
WALL_LIMIT_S = 900.0
#: Simulated seconds the cell settles after a reset before the next objective starts.
SETTLE_S = 0.3

Outcome = Literal["succeeded", "kept running", "failed", "cannot load"]


@dataclass(frozen=True)
class FileVerdict:
    """One objective file of the checked folder.

    Attributes:
        path: the file, relative to the checked folder.
        objectives: the IDs it defines (MoveIt Pro's files define one).
        runnable: those of them that are runnable (not subtree-only).
        problem: why it does not validate (``file:line: message``), None when it does.
        warnings: what validates but will fail where it runs (a waypoint the config has not saved).
    """

    path: Path
    objectives: tuple[str, ...]
    runnable: tuple[str, ...]
    problem: str | None
    warnings: tuple[str, ...] = ()

    @property
    def valid(self) -> bool:
        """True when the file validates with its SubTree closure."""
        return self.problem is None


@dataclass(frozen=True)
class RunVerdict:
    """How one runnable objective did.

    Attributes:
        objective: its ID.
        outcome: ``succeeded``; ``kept running`` (still running without failure at the time limit, then
            cancelled); ``failed`` (failed, or cancelled by something else); ``cannot load``.
        message: the failure or validation message ("" on success).
        sim_seconds: simulated time it ran.
        wall_seconds: wall time it ran.
    """

    objective: str
    outcome: Outcome
    message: str = ""
    sim_seconds: float = 0.0
    wall_seconds: float = 0.0

    @property
    def ok(self) -> bool:
        """True when it succeeded or kept running until the time limit."""
        return self.outcome in ("succeeded", "kept running")

    def to_json(self) -> dict[str, Any]:
        return {
            "objective": self.objective,
            "outcome": self.outcome,
            "message": self.message,
            "sim_seconds": round(self.sim_seconds, 3),
            "wall_seconds": round(self.wall_seconds, 3),
        }


@dataclass
class CheckReport:
    """The verdicts of a check: every file, and every runnable objective when they were run."""

    folder: Path
    config: str
    files: list[FileVerdict]
    runs: list[RunVerdict] | None = None

    @property
    def runnable(self) -> list[str]:
        """The runnable objectives of the folder's files, in file order."""
        return [objective for verdict in self.files for objective in verdict.runnable]

    def counts(self) -> dict[str, int]:
        """``files``, ``valid``, ``runnable``, and once run ``ran_ok`` (succeeded or kept running),
        ``succeeded``, ``kept_running``, ``failed``, ``cannot_load``."""
        counts = {
            "files": len(self.files),
            "valid": sum(verdict.valid for verdict in self.files),
            "runnable": len(self.runnable),
        }
        if self.runs is not None:
            outcomes = [run.outcome for run in self.runs]
            counts["ran_ok"] = sum(run.ok for run in self.runs)
            counts["succeeded"] = outcomes.count("succeeded")
            counts["kept_running"] = outcomes.count("kept running")
            counts["failed"] = outcomes.count("failed")
            counts["cannot_load"] = outcomes.count("cannot load")
        return counts

    def summary(self) -> str:
        """One or two lines: how many files validate, and how many runnable objectives ran correctly."""
        counts = self.counts()
        lines = [f"{counts['valid']} of {counts['files']} objective files validate against {self.config}"]
        if self.runs is not None:
            kept = counts["kept_running"]
            loops = f", {kept} of them kept running until the time limit" if kept else ""
            of = len(self.runs)
            runnable = "runnable objectives" if of == counts["runnable"] else "runnable objectives that ran"
            lines.append(
                f"{counts['ran_ok']} of the {of} {runnable} succeed{loops} "
                f"({counts['failed']} failed, {counts['cannot_load']} cannot load)"
            )
        return "\n".join(lines)

    def to_json(self) -> dict[str, Any]:
        return {
            "folder": str(self.folder),
            "config": self.config,
            "counts": self.counts(),
            "files": [
                {
                    "file": str(verdict.path),
                    "objectives": list(verdict.objectives),
                    "runnable": list(verdict.runnable),
                    "problem": verdict.problem,
                    "warnings": list(verdict.warnings),
                }
                for verdict in self.files
            ],
            "runs": None if self.runs is None else [run.to_json() for run in self.runs],
        }


def objective_folder(path: Path) -> Path:
    """The folder of objective files ``path`` names: itself, or its ``objectives/`` when it is a package
    (MoveIt Pro's config packages keep their objectives there).

    Raises:
        ConfigError: no such folder, or no objective XML in it.
    """
    folder = Path(path).expanduser().resolve()
    if not folder.is_dir():
        raise ConfigError(f"{path} is not a folder")
    package = (folder / "package.xml").is_file()  # a package's own XML files (package.xml, scenes) are none
    if (folder / "objectives").is_dir() and (package or not any(folder.glob("*.xml"))):
        folder = folder / "objectives"
    if not any(folder.rglob("*.xml")):
        raise ConfigError(f"{folder} holds no objective XML files")
    return folder


@dataclass
class CheckWorkspace:
    """A temporary workspace whose package ``kinema_objective_check`` (based on ``config``) holds copies
    of the checked folder and of the folders its SubTrees reach.

    Use :meth:`create`; the caller owns ``root`` (a temporary folder) and removes it.
    """

    root: Path
    config: str
    source: Path
    objectives: Path
    # copy -> original, for every folder copied (so messages name the user's files, not the copies)
    copies: dict[Path, Path] = field(default_factory=dict)

    @classmethod
    def create(
        cls,
        root: Path,
        folder: Path,
        config: str,
        workspace: Path | None = None,
        subtree_folders: tuple[Path, ...] = (),
    ) -> CheckWorkspace:
        """Lay the workspace out in the empty folder ``root``.

        Args:
            root: where (an empty or missing folder).
            folder: the objectives to check (see :func:`objective_folder`).
            config: the config package to check against (its behaviors, robot, simulation, waypoints).
            workspace: the user's workspace, whose packages (``config`` among them, perhaps) stay visible.
            subtree_folders: more objective folders the checked ones reach through SubTrees (not counted).

        Raises:
            ConfigError: a folder is missing, or ``config`` does not resolve.
        """
        from kinema.config import Workspace, resolve_config
        from kinema.config.workspace import find_workspace_root

        source = objective_folder(folder)
        src = root / "src"
        src.mkdir(parents=True, exist_ok=True)
        if workspace is not None:
            user_src = find_workspace_root(workspace) / "src"
            for entry in sorted(user_src.iterdir()):
                if not entry.name.startswith(".") and entry.name not in (CHECK_PACKAGE, SUBTREES_PACKAGE):
                    (src / entry.name).symlink_to(entry.resolve(), target_is_directory=entry.is_dir())
        copies: dict[Path, Path] = {}
        parent = config
        if subtree_folders:
            # The folders SubTrees reach form a package between the config and the checked folder, so the
            # checked folder's objectives win over theirs and the config's, and saves go to the folder.
            helpers = src / SUBTREES_PACKAGE
            libraries: dict[str, Any] = {}
            for index, extra in enumerate(subtree_folders):
                name = f"subtrees_{index}"
                copies[helpers / name] = objective_folder(extra)
                shutil.copytree(copies[helpers / name], helpers / name)
                libraries[f"checked_{name}"] = {"package_name": SUBTREES_PACKAGE, "relative_path": name}
            _write_package(helpers, SUBTREES_PACKAGE, config, libraries, f"Subtrees reached from {source}")
            parent = SUBTREES_PACKAGE
        package = src / CHECK_PACKAGE
        objectives = package / "objectives"
        shutil.copytree(source, objectives)
        copies = {objectives: source, **copies}
        libraries = {"checked_objectives": {"package_name": CHECK_PACKAGE, "relative_path": "objectives"}}
        _write_package(
            package, CHECK_PACKAGE, parent, libraries, f"Objectives of {source}, checked against {config}"
        )
        checked = cls(root=root, config=config, source=source, objectives=objectives, copies=copies)
        resolve_config(CHECK_PACKAGE, Workspace.discover(root))  # a bad config name fails here, once
        return checked

    def originals(self, text: str) -> str:
        """``text`` with the copies' paths replaced by the folders they copy."""
        for copy, original in self.copies.items():
            text = text.replace(str(copy), str(original))
        return text

    def restore(self) -> list[Path]:
        """Put the copies back as the folders they copy are (files objectives saved are undone), so each
        run starts from the library as shipped; returns the files changed."""
        changed: list[Path] = []
        for copy, original in self.copies.items():
            for path in sorted(copy.rglob("*"), reverse=True):
                source = original / path.relative_to(copy)
                if path.is_file() and not source.exists():
                    path.unlink()
                    changed.append(path)
            for source in original.rglob("*"):
                if not source.is_file():
                    continue
                path = copy / source.relative_to(original)
                if not path.is_file() or path.read_bytes() != source.read_bytes():
                    path.parent.mkdir(parents=True, exist_ok=True)
                    shutil.copy2(source, path)
                    changed.append(path)
        return changed

    def resolved(self) -> ResolvedConfig:
        """The check package resolved with its inheritance chain."""
        from kinema.config import Workspace, resolve_config

        return resolve_config(CHECK_PACKAGE, Workspace.discover(self.root))

    def files(self) -> list[Path]:
        """The checked folder's objective files (sub-folders included), sorted."""
        return sorted(path for path in self.objectives.rglob("*.xml") if not _hidden(path, self.objectives))

    def validate(self) -> list[FileVerdict]:
        """Validate each file with its SubTree closure against the config's behaviors.

        Raises:
            PluginError: a behavior plugin of the config does not load.
        """
        from kinema.config import ObjectiveLibrary
        from kinema.config.waypoint_uses import saved_waypoint_names, unknown_waypoint_warnings
        from kinema.plugins import BehaviorHost
        from kinema.runtime.library_check import file_problem

        resolved = self.resolved()
        library = ObjectiveLibrary.load(resolved)
        host = BehaviorHost.for_config(resolved)
        host.load().raise_for_errors()
        factory = host.registry.create_factory()
        by_file = _objectives_by_file(library)
        unreadable = {
            Path(error.location.file).resolve(): str(error) for error in library.errors if error.location
        }
        # Read once for every file (the waypoints file is the config's, not the checked file's).
        known_waypoints = saved_waypoint_names(resolved)
        verdicts = []
        for path in self.files():
            defined = by_file.get(path.resolve(), [])
            # Validated even when the library could not load it: every problem is counted, not only the one
            # that stopped the load (a missing parameter file hid nine more in a MoveIt Pro objective).
            problem = file_problem(library, path, factory) or unreadable.get(path.resolve())
            waypoint_warnings: list[str] = []
            if known_waypoints is not None:
                waypoint_warnings = unknown_waypoint_warnings([path], known_waypoints, self.config)
            verdicts.append(
                FileVerdict(
                    path=path.relative_to(self.objectives),
                    objectives=tuple(info.id for info in defined),
                    runnable=tuple(info.id for info in defined if info.runnable),
                    problem=None if problem is None else self.originals(problem),
                    warnings=tuple(map(self.originals, waypoint_warnings)),
                )
            )
        return verdicts


def _write_package(
    folder: Path, name: str, based_on: str, libraries: dict[str, Any], description: str
) -> None:
    """A config package ``name`` in ``folder``, based on ``based_on``, with these objective libraries."""
    from xml.sax.saxutils import escape

    (folder / "config").mkdir(parents=True, exist_ok=True)
    (folder / "package.xml").write_text(
        f'<?xml version="1.0"?>\n<package format="3"><name>{name}</name><version>0.0.0</version>'
        f"<description>{escape(description)}</description>"
        "<maintainer email='kinema@example.com'>kinema</maintainer><license>none</license></package>\n"
    )
    settings = {"based_on_package": based_on, "objectives": {"objective_library_paths": libraries}}
    (folder / "config" / "config.yaml").write_text(yaml.safe_dump(settings, sort_keys=False))


def _hidden(path: Path, folder: Path) -> bool:
    return any(part.startswith(".") for part in path.relative_to(folder).parts)


def _objectives_by_file(library: ObjectiveLibrary) -> dict[Path, list[Any]]:
    by_file: dict[Path, list[Any]] = {}
    for info in library.objectives.values():
        by_file.setdefault(Path(info.file).resolve(), []).append(info)
    for infos in by_file.values():
        infos.sort(key=lambda info: info.line)
    return by_file


class CheckCell:
    """The check workspace's config running headless (drivers and agent, as ``kinema run --headless
    --sim-speed max --auto-approve`` on a free loopback port), one objective at a time.

    Use it as a context manager. ``node`` is a transport node of this process, for a caller's own
    measurements (topics, the simulator's services).
    """

    def __init__(
        self, checked: CheckWorkspace, *, sim_speed: str = "max", echo: Callable[[str], None] | None = None
    ) -> None:
        self.checked = checked
        self.sim_speed = sim_speed
        self._echo = echo or (lambda _text: None)
        self.launcher: Launcher | None = None
        self.client: ObjectiveClient | None = None
        self.node: Node | None = None
        self.sim: Any = None
        self.keyframe = ""
        self._clock: Any = None
        self._startup_controllers: set[str] = set()
        self._known_controllers: set[str] = set()
        self._previous_approve: str | None = None
        self._resettable_scene = True

    def __enter__(self) -> CheckCell:
        try:
            self.start()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def simulated(self) -> bool:
        """True when the config runs a simulator (time limits are then simulated seconds)."""
        return self.sim is not None

    def start(self) -> None:
        """Start the drivers and the agent; returns once objectives can be started.

        Raises:
            KinemaError: the runtime did not start (the message carries the end of its log).
        """
        from kinema.drivers.mujoco import names as driver_names
        from kinema.runtime.launcher import Launcher, LaunchOptions
        from kinema.runtime.sim_clock import SimClock
        from kinema.sdk import ObjectiveClient
        from kinema.transport import Node, free_endpoint

        self._previous_approve = os.environ.get("KINEMA_AUTO_APPROVE")
        # Read by the approval behaviors of the agent, which inherits this environment.
        os.environ["KINEMA_AUTO_APPROVE"] = "1"
        resolved = self.checked.resolved()
        options = LaunchOptions(
            config=CHECK_PACKAGE,
            workspace=self.checked.root,
            endpoint=free_endpoint(),
            sim_speed=self.sim_speed,
            record=False,
            echo=self._echo,
        )
        self.launcher = Launcher(options)
        self.launcher.start()
        session = self.launcher.session
        assert session is not None
        self.node = Node(session, f"kinema_objective_check_{os.getpid()}")
        self.client = ObjectiveClient(session=session, timeout=30.0)
        self.client.wait_for_runtime(60.0)
        if resolved.mujoco_model_path is not None:
            from kinema.drivers.mujoco.client import SimClient

            self._clock = SimClock()
            self.node.create_subscription(
                driver_names.CLOCK_TYPE, driver_names.CLOCK_TOPIC, self._clock.on_clock_message
            )
            self._clock.wait_until_running(30.0)
            self.sim = SimClient(self.node, timeout=30.0)
            _names, self.keyframe = self.sim.keyframes()
        self._startup_controllers, self._known_controllers = self._controllers()

    def close(self) -> None:
        """Stop the runtime (drivers, agent, router)."""
        if self.client is not None:
            self.client.close()
            self.client = None
        if self.launcher is not None:
            self.launcher.stop()
            self.launcher = None
        if self._previous_approve is None:
            os.environ.pop("KINEMA_AUTO_APPROVE", None)
        else:
            os.environ["KINEMA_AUTO_APPROVE"] = self._previous_approve

    def sim_time(self) -> float:
        """The simulator's time (s); wall time without a simulator."""
        return self._clock.now() if self._clock is not None else time.monotonic()

    # -- reset --------------------------------------------------------------------------------------

    def _controllers(self) -> tuple[set[str], set[str]]:
        """(active, all) controller names the controller manager reports; empty sets without one."""
        from kinema.drivers.mujoco import names as driver_names

        assert self.node is not None
        client = self.node.create_client(
            driver_names.LIST_CONTROLLERS_TYPE, driver_names.LIST_CONTROLLERS_SERVICE
        )
        try:
            if not client.wait_for_service(5.0):
                return set(), set()
            states = client.call({}, timeout=10.0).controller
        except TransportError:
            return set(), set()
        finally:
            client.close()
        return {str(c.name) for c in states if str(c.state) == "active"}, {str(c.name) for c in states}

    def reset(self) -> None:
        """Put the cell back as it started: the checked folder as shipped (files objectives saved are
        undone), simulation at its start keyframe, startup controllers active, no collision objects added
        by objectives.

        Raises:
            KinemaError: the simulator or the controller manager refused.
        """
        assert self.client is not None and self.node is not None
        self.client.cancel()  # a run a caller left going (run() waits for its own)
        self.checked.restore()
        if self.sim is not None and self.keyframe:
            self.sim.set_state(keyframe=self.keyframe)
        if self._known_controllers:
            self._restore_controllers()
        if self._resettable_scene:
            result = self.client.start(xml=_RESET_SCENE_XML).result(30.0)
            if not result.succeeded:
                log.warning("the planning scene could not be reset (%s); not trying again", result)
                self._resettable_scene = False
        self._wait_sim(SETTLE_S)

    def _restore_controllers(self) -> None:
        from kinema.drivers.mujoco import names as driver_names

        assert self.node is not None
        active, _known = self._controllers()
        if active == self._startup_controllers:
            return
        client = self.node.create_client(
            driver_names.SWITCH_CONTROLLERS_TYPE, driver_names.SWITCH_CONTROLLERS_SERVICE
        )
        try:
            answer = client.call(
                {
                    "activate_controllers": sorted(self._startup_controllers - active),
                    "deactivate_controllers": sorted(active - self._startup_controllers),
                    "strictness": 1,
                },
                timeout=10.0,
            )
        finally:
            client.close()
        if not answer.ok:
            raise KinemaError(f"the startup controllers could not be restored: {answer.message}")

    def _wait_sim(self, seconds: float) -> None:
        start = self.sim_time()
        deadline = time.monotonic() + 10.0
        while self.sim_time() - start < seconds and time.monotonic() < deadline:
            time.sleep(0.01)

    # -- run ------------------------------------------------------------------------------------------

    def run(
        self, objective: str, time_limit: float = DEFAULT_TIME_LIMIT_S, *, reset: bool = True
    ) -> RunVerdict:
        """Reset the cell (unless ``reset`` is False) and run ``objective`` until it ends or has run
        ``time_limit`` seconds of sim time (then it is cancelled: "kept running")."""
        assert self.client is not None
        if reset:
            self.reset()
        handle = self.client.start(objective)
        wall_start, sim_start = time.monotonic(), self.sim_time()
        kept_running = False
        while not handle.done:
            elapsed = self.sim_time() - sim_start
            wall = time.monotonic() - wall_start
            if (elapsed >= time_limit and wall >= MIN_WALL_S) or wall >= WALL_LIMIT_S:
                kept_running = handle.cancel(timeout=30.0)
                break
            time.sleep(0.05)
        try:
            result = handle.result(60.0)
        except TransportError as error:
            return RunVerdict(objective, "failed", f"no result: {error}", self.sim_time() - sim_start)
        sim_seconds = self.sim_time() - sim_start
        wall_seconds = time.monotonic() - wall_start
        if result.succeeded:
            return RunVerdict(objective, "succeeded", "", sim_seconds, wall_seconds)
        if kept_running and result.cancelled:
            return RunVerdict(objective, "kept running", "", sim_seconds, wall_seconds)
        message = self.checked.originals(result.error_message or str(result))
        return RunVerdict(objective, "failed", message, sim_seconds, wall_seconds)


_RESET_SCENE_XML = """<root BTCPP_format="4" main_tree_to_execute="Objective Check Reset">
  <BehaviorTree ID="Objective Check Reset">
    <Action ID="ResetPlanningSceneObjects" />
  </BehaviorTree>
</root>"""


def check_folder(
    folder: Path,
    config: str,
    *,
    workspace: Path | None = None,
    subtree_folders: tuple[Path, ...] = (),
    run: bool = False,
    time_limit: float = DEFAULT_TIME_LIMIT_S,
    only: tuple[str, ...] = (),
    sim_speed: str = "max",
    scratch: Path | None = None,
    on_file: Callable[[FileVerdict], None] | None = None,
    on_run: Callable[[RunVerdict], None] | None = None,
    echo: Callable[[str], None] | None = None,
) -> CheckReport:
    """Validate ``folder``'s objectives against ``config`` and, with ``run``, run each runnable one.

    Args:
        folder: the objectives (see :func:`objective_folder`).
        config: the config package to check against.
        workspace: the user's workspace (None: only bundled packages).
        subtree_folders: folders of objectives the checked ones reach through SubTrees.
        run: also run the runnable objectives (needs a config that can run headless, e.g. simulated).
        time_limit: simulated seconds each objective may run (see :class:`CheckCell`).
        only: run only these objective IDs (all runnable ones when empty).
        sim_speed: the simulation's speed while they run (``max``, or a factor such as ``1``).
        scratch: the folder for the temporary workspace (None: a new temporary folder, removed after).
        on_file, on_run: called with each verdict as it is known (progress).
        echo: the runtime's progress lines.
    """
    with _scratch(scratch) as root:
        checked = CheckWorkspace.create(root, folder, config, workspace, subtree_folders)
        files = checked.validate()
        for verdict in files:
            if on_file is not None:
                on_file(verdict)
        report = CheckReport(checked.source, config, files)
        if not run:
            return report
        problems = {objective: verdict.problem for verdict in files for objective in verdict.runnable}
        wanted = [objective for objective in report.runnable if not only or objective in only]
        unknown = sorted(set(only) - set(report.runnable))
        if unknown:
            raise ConfigError(
                f"no runnable objective {unknown[0]!r} in {checked.source}; runnable ones: "
                + ", ".join(report.runnable)
            )
        report.runs = []
        with CheckCell(checked, sim_speed=sim_speed, echo=echo) as cell:
            for objective in wanted:
                problem = problems[objective]
                outcome = (
                    RunVerdict(objective, "cannot load", problem)
                    if problem is not None
                    else cell.run(objective, time_limit)
                )
                report.runs.append(outcome)
                if on_run is not None:
                    on_run(outcome)
        return report


class _scratch:
    """A context giving ``scratch`` (created) or a new temporary folder removed afterwards."""

    def __init__(self, scratch: Path | None) -> None:
        self._given = scratch
        self._made: Any = None

    def __enter__(self) -> Path:
        if self._given is not None:
            self._given.mkdir(parents=True, exist_ok=True)
            return self._given
        import tempfile

        self._made = tempfile.TemporaryDirectory(prefix="kinema-objective-check-")
        return Path(self._made.name)

    def __exit__(self, *exc: object) -> None:
        if self._made is not None:
            self._made.cleanup()


__all__ = [
    "CHECK_PACKAGE",
    "DEFAULT_TIME_LIMIT_S",
    "CheckCell",
    "CheckReport",
    "CheckWorkspace",
    "FileVerdict",
    "RunVerdict",
    "check_folder",
    "objective_folder",
]
