"""Workspaces and the packages in them.

A workspace is a folder with ``src/``; every package under ``src/`` (found at any depth, as colcon does)
plus Kinema's bundled packages is visible. A folder is a package when it holds ``config/config.yaml``
(a config package), ``package.xml`` or ``pyproject.toml`` (a behavior or other package); its name is the
``<name>`` of its ``package.xml`` when there is one, the folder name otherwise. Scanning does not descend
into a package, nor into hidden folders, ``build``/``install``/``log`` and folders with ``COLCON_IGNORE``.

Bundled packages are the config packages under Kinema's ``configs/`` and the core objective library:
Kinema's top-level ``objectives/`` folder, which is the package ``kinema_objectives``. It also answers to
MoveIt Pro's name ``moveit_pro_objectives``, so a config.yaml written for MoveIt Pro resolves unchanged.
MoveIt Pro splits that library into ``objectives/core``, ``objectives/motion``, ``objectives/mujoco``, ...;
Kinema's core library is one folder, so for this package a relative path ``objectives`` (or ``.``) is the
library folder itself and ``objectives/<part>`` is its sub-folder ``<part>`` when that exists, otherwise
the whole library folder (several such entries then name the same folder, which is loaded once).

A workspace package named like a bundled one overlays it, with a notice (a ROS overlay over its underlay);
two packages of the same name inside the workspace are an error that names both paths. A package with a
``KINEMA_IGNORE`` or ``MOVEIT_PRO_IGNORE`` marker file is hidden from the list of config packages
(it stays usable, e.g. as the parent of another config).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from kinema.errors import ConfigError, did_you_mean
from kinema.resources import bundled_dir

CORE_OBJECTIVES_PACKAGE = "kinema_objectives"
CORE_OBJECTIVES_ALIASES = ("moveit_pro_objectives",)
IGNORE_MARKERS = ("KINEMA_IGNORE", "MOVEIT_PRO_IGNORE")
_SKIPPED_FOLDERS = frozenset({"build", "install", "log", "__pycache__", "node_modules"})
_PACKAGE_MARKERS = ("package.xml", "pyproject.toml")
_MAX_SCAN_DEPTH = 6
_NAME_IN_PACKAGE_XML = re.compile(rb"<name>\s*([^<\s]+)\s*</name>")


@dataclass(frozen=True)
class Package:
    """One package a workspace can see.

    Attributes:
        name: the package name (``package.xml`` ``<name>``, else the folder name).
        path: the package folder.
        origin: ``"workspace"`` or ``"bundled"``.
        kind: ``"config"`` (has config/config.yaml), ``"objectives"`` (the core objective library) or
            ``"other"`` (e.g. a behavior package).
        hidden: a ``KINEMA_IGNORE``/``MOVEIT_PRO_IGNORE`` marker hides it from the config list.
    """

    name: str
    path: Path
    origin: str
    kind: str
    hidden: bool = False

    @property
    def config_file(self) -> Path:
        """The package's ``config/config.yaml`` (it exists when ``kind == "config"``)."""
        return self.path / "config" / "config.yaml"

    @property
    def is_config(self) -> bool:
        """True for a config package."""
        return self.kind == "config"

    def resolve_relative(self, relative: str) -> Path:
        """Return the path ``relative`` names inside this package (see the module docstring for the
        core objective library's mapping of MoveIt Pro's ``objectives/<part>`` folders)."""
        relative = relative.strip()
        if self.kind != "objectives":
            return self.path / relative
        parts = [part for part in Path(relative).parts if part not in (".", "")]
        if parts and parts[0] == "objectives":
            parts = parts[1:]
        candidate = self.path.joinpath(*parts) if parts else self.path
        if parts and not candidate.exists() and len(parts) == 1:
            return self.path  # MoveIt Pro's sub-libraries all fold into Kinema's one core library
        return candidate


@dataclass
class Workspace:
    """The packages visible from one workspace (its own and the bundled ones).

    Use :meth:`discover` to build one. ``root`` is None when no workspace is selected (only bundled
    packages are visible then).
    """

    root: Path | None
    packages: dict[str, Package] = field(default_factory=dict)
    aliases: dict[str, str] = field(default_factory=dict)
    notices: list[str] = field(default_factory=list)

    @classmethod
    def discover(cls, path: str | Path | None = None) -> Workspace:
        """Build the workspace rooted at ``path`` (or an ancestor of it that has ``src/``).

        Args:
            path: a workspace folder or a folder inside one; None means the active workspace
                (``KINEMA_WORKSPACE`` or the one stored by ``kinema configure``), and when none is
                set, only the bundled packages.

        Raises:
            ConfigError: ``path`` is not inside a workspace, or two workspace packages share a name.
        """
        if path is None:
            from kinema.config.selection import active_selection

            selected = active_selection().workspace
            root = find_workspace_root(selected) if selected is not None else None
        else:
            root = find_workspace_root(Path(path))
        workspace = cls(root=root)
        workspace._add_bundled()
        if root is not None:
            workspace._add_workspace_packages(root / "src")
        return workspace

    @classmethod
    def bundled_only(cls) -> Workspace:
        """A workspace that sees only Kinema's bundled packages."""
        workspace = cls(root=None)
        workspace._add_bundled()
        return workspace

    def package(self, name: str) -> Package:
        """Return the package called ``name`` (or one of its aliases).

        Raises:
            ConfigError: no such package; the message lists the known ones.
        """
        found = self.packages.get(self.aliases.get(name, name))
        if found is None:
            raise ConfigError(
                f"no package named {name!r} in {self.describe()}; {did_you_mean(name, self.packages)}"
            )
        return found

    def has_package(self, name: str) -> bool:
        """True when ``name`` (or an alias) names a visible package."""
        return self.aliases.get(name, name) in self.packages

    def config_packages(self, *, include_hidden: bool = False) -> list[Package]:
        """The config packages, sorted by name; hidden ones only when ``include_hidden``."""
        return sorted(
            (p for p in self.packages.values() if p.is_config and (include_hidden or not p.hidden)),
            key=lambda p: p.name,
        )

    def describe(self) -> str:
        """A short description for messages: the workspace folder, or that only bundled packages are seen."""
        return (
            f"workspace {self.root}"
            if self.root is not None
            else "the bundled packages (no workspace selected)"
        )

    def _add_bundled(self) -> None:
        core = bundled_dir("objectives")
        self.packages[CORE_OBJECTIVES_PACKAGE] = Package(
            CORE_OBJECTIVES_PACKAGE, core, "bundled", "objectives"
        )
        for alias in CORE_OBJECTIVES_ALIASES:
            self.aliases[alias] = CORE_OBJECTIVES_PACKAGE
        configs = bundled_dir("configs")
        for package in _scan(configs, "bundled") if configs.is_dir() else []:
            self.packages[package.name] = package

    def _add_workspace_packages(self, src: Path) -> None:
        seen: dict[str, Package] = {}
        for package in _scan(src, "workspace"):
            if package.name in seen:
                first, second = sorted((seen[package.name].path, package.path))
                raise ConfigError(
                    f"two packages are named {package.name!r} in the workspace: {first} and {second}; "
                    "rename or remove one of them"
                )
            seen[package.name] = package
        for name, package in sorted(seen.items()):
            canonical = self.aliases.pop(name, name)
            bundled = self.packages.get(canonical)
            if bundled is not None and bundled.origin == "bundled":
                self.notices.append(
                    f"the workspace package {name!r} ({package.path}) "
                    f"overlays the bundled one ({bundled.path})"
                )
                if canonical != name:  # the workspace overlays an alias: the bundled name stays reachable
                    self.packages[name] = package
                    continue
            self.packages[name] = package


def find_workspace_root(path: Path) -> Path:
    """Return the workspace ``path`` names: ``path`` itself when it has ``src/``, or the workspace whose
    ``src/`` contains ``path`` (e.g. a package folder).

    An unrelated ancestor with a ``src/`` (such as a home folder with ``~/src``) is not taken for a
    workspace.

    Raises:
        ConfigError: ``path`` is not a workspace (the message suggests ``kinema init``).
    """
    start = path.expanduser().resolve()
    if not start.exists():
        raise ConfigError(f"the workspace folder {start} does not exist; create it with `kinema init {path}`")
    if (start / "src").is_dir():
        return start
    for candidate in start.parents:
        if (candidate / "src").is_dir() and start.is_relative_to(candidate / "src"):
            return candidate
    raise ConfigError(
        f"{start} is not a workspace (it has no src/ folder); create one with `kinema init {path}`"
    )


def select_workspace_hint() -> str:
    """How to select a workspace, for a message saying that none is: the one the current folder is in
    when it is in one (a user who ran ``kinema init ws && cd ws``), else how to select or create one."""
    here = Path.cwd()
    try:
        root = find_workspace_root(here)
    except (ConfigError, OSError):
        return (
            "pass -w PATH, or select one with `kinema configure -w PATH` (create one with `kinema init PATH`)"
        )
    where = "." if root == here.resolve() else str(root)
    return (
        f"you are in the workspace {root}: pass -w {where}, or select it for later commands with "
        f"`kinema configure -w {where}`"
    )


def _scan(folder: Path, origin: str) -> list[Package]:
    """Find the packages under ``folder`` (not descending into a package)."""
    found: list[Package] = []
    stack: list[tuple[Path, int]] = [(folder, 0)]
    while stack:
        current, depth = stack.pop()
        try:
            entries = sorted(os.scandir(current), key=lambda entry: entry.name)
        except OSError:
            continue
        names = {entry.name for entry in entries}
        if "COLCON_IGNORE" in names and current != folder:
            continue
        is_config = (current / "config" / "config.yaml").is_file()
        if current != folder and (is_config or any(marker in names for marker in _PACKAGE_MARKERS)):
            found.append(
                Package(
                    name=_package_name(current, names),
                    path=current,
                    origin=origin,
                    kind="config" if is_config else "other",
                    hidden=any(marker in names for marker in IGNORE_MARKERS),
                )
            )
            continue
        if depth >= _MAX_SCAN_DEPTH:
            continue
        for entry in reversed(entries):
            if entry.is_dir() and not entry.name.startswith(".") and entry.name not in _SKIPPED_FOLDERS:
                stack.append((Path(entry.path), depth + 1))
    return found


def _package_name(folder: Path, names: set[str]) -> str:
    if "package.xml" in names:
        try:
            match = _NAME_IN_PACKAGE_XML.search((folder / "package.xml").read_bytes()[:65536])
        except OSError:
            match = None
        if match:
            return match.group(1).decode("utf-8", "replace")
    return folder.name


def list_config_packages(
    workspace: Workspace | None = None, *, include_hidden: bool = False
) -> list[Package]:
    """The config packages visible from ``workspace`` (default: the active one), sorted by name.

    This is what ``kinema config list`` (and ``kinema run --list``) print.
    """
    return (workspace or Workspace.discover()).config_packages(include_hidden=include_hidden)
