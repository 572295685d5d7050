"""Where behavior plugins come from and which of them a config activates.

Three sources, all described the same way — a name (the *loader name* a config lists in
``objectives.behavior_loader_plugins``) and a module implementing the hooks:

* **bundled**: the folders of Kinema's ``plugins/`` (core, mujoco, examples);
* **entry points**: installed distributions declaring ``[project.entry-points."kinema.behaviors"]``;
* **workspace**: behavior packages under a workspace's ``src/``, loaded by path so they hot-reload
  without a reinstall.

Bundled and workspace plugins are *behavior packages*: a folder with a ``pyproject.toml`` whose
``kinema.behaviors`` entry-point table maps each loader name to the module that implements the hooks,
so a package scaffolded into a workspace looks exactly like a bundled one. A workspace package overlays
an entry point or a bundled plugin of the same loader name, as a ROS overlay does its underlay.
"""

from __future__ import annotations

import enum
import re
import tomllib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

from kinema.errors import KinemaError, PluginError, SourceLocation, did_you_mean

ENTRY_POINT_GROUP = "kinema.behaviors"

# MoveIt Pro's (and MoveIt Studio's) loaders that Kinema provides under its own name, so a config
# written for MoveIt Pro activates the equivalent Kinema plugin.
LOADER_ALIASES: Mapping[str, str] = {
    "moveit_pro::behaviors::CoreBehaviorsLoader": "kinema::CoreBehaviorsLoader",
    "moveit_pro::behaviors::MujocoBehaviorsLoader": "kinema::MujocoBehaviorsLoader",
    # MoveIt Pro's MPC behaviors are in Kinema's core plugin (family mpc).
    "moveit_pro::behaviors::MPCBehaviorsLoader": "kinema::CoreBehaviorsLoader",
    "moveit_studio::behaviors::CoreBehaviorsLoader": "kinema::CoreBehaviorsLoader",
    "moveit_studio::behaviors::MujocoBehaviorsLoader": "kinema::MujocoBehaviorsLoader",
}
_MOVEIT_PREFIXES = ("moveit_pro::", "moveit_studio::")
_SKIPPED_DIRS = {"build", "install", "log", "node_modules", "__pycache__"}


class PluginSource(enum.StrEnum):
    """Where a plugin was found (shown by ``kinema plugins``)."""

    BUNDLED = "bundled"
    ENTRY_POINT = "entry point"
    WORKSPACE = "workspace"


@dataclass(frozen=True)
class PluginSpec:
    """A plugin that can be loaded.

    Attributes:
        name: the loader name, e.g. ``kinema::ExampleBehaviorsLoader``.
        source: where it was found.
        module: the dotted module implementing the hooks, relative to ``root`` for path-loaded
            plugins (``my_pkg`` or ``my_pkg.register``), absolute for entry points.
        package: the behavior package (or distribution) name, for messages and ``--packages-select``.
        root: the behavior package folder (holds ``pyproject.toml``); None for entry points.
        attribute: for entry points ``module:attribute``, the attribute holding the plugin object.
    """

    name: str
    source: PluginSource
    module: str
    package: str
    root: Path | None = None
    attribute: str | None = None

    @property
    def hot_reloadable(self) -> bool:
        """Path-loaded plugins are re-imported when their files change."""
        return self.root is not None and self.source is PluginSource.WORKSPACE

    @property
    def where(self) -> str:
        """A short human-readable origin: the folder, or the distribution of an entry point."""
        return str(self.root) if self.root is not None else f"{self.package} ({self.module})"


def default_loader_name(package: str) -> str:
    """Return the loader name a scaffolded package gets: ``my_pkg`` → ``my_pkg::MyPkgBehaviorsLoader``.

    A trailing ``_behaviors`` is not doubled (``lab_sim_behaviors`` → ``LabSimBehaviorsLoader``), which is
    MoveIt Pro's own naming.
    """
    stem = re.sub(r"_?behaviors$", "", package) or package
    camel = "".join(part[:1].upper() + part[1:] for part in stem.split("_") if part)
    return f"{package}::{camel}BehaviorsLoader"


def read_behavior_package(folder: Path, source: PluginSource) -> list[PluginSpec]:
    """Return the plugins a behavior package folder declares (empty if it is not a behavior package).

    Raises:
        PluginError: the ``pyproject.toml`` cannot be parsed or names a module that is not there.
    """
    pyproject = folder / "pyproject.toml"
    if not pyproject.is_file():
        return []
    try:
        data = tomllib.loads(pyproject.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as error:
        line = _toml_error_line(error)
        raise PluginError(
            f"cannot parse {pyproject.name}: {error}", location=SourceLocation(str(pyproject), line)
        ) from None
    project = data.get("project", {})
    table = project.get("entry-points", {}).get(ENTRY_POINT_GROUP)
    if not table:
        return []
    package = str(project.get("name", folder.name))
    specs = []
    for name, target in table.items():
        module, _, attribute = str(target).partition(":")
        module = module.strip()
        top = module.split(".")[0]
        if not (folder / top / "__init__.py").is_file():
            raise PluginError(
                f"behavior package '{package}' declares loader '{name}' = '{target}', but "
                f"{folder / top / '__init__.py'} does not exist",
                location=SourceLocation(str(pyproject)),
            )
        specs.append(PluginSpec(name, source, module, package, folder.resolve(), attribute.strip() or None))
    return specs


def _toml_error_line(error: tomllib.TOMLDecodeError) -> int:
    match = re.search(r"line (\d+)", str(error))
    return int(match.group(1)) if match else 0


def behavior_package_dirs(search_root: Path, depth: int = 2) -> list[Path]:
    """Folders under ``search_root`` (up to ``depth`` levels) that hold a ``pyproject.toml``."""
    found: list[Path] = []
    if not search_root.is_dir():
        return found
    for child in sorted(search_root.iterdir()):
        if not child.is_dir() or child.name.startswith(".") or child.name in _SKIPPED_DIRS:
            continue
        if (child / "pyproject.toml").is_file():
            found.append(child)
        elif depth > 1:
            found.extend(behavior_package_dirs(child, depth - 1))
    return found


def bundled_plugins() -> list[PluginSpec]:
    """The plugins shipped with Kinema in ``plugins/``."""
    from kinema.resources import bundled_dir

    specs: list[PluginSpec] = []
    for folder in behavior_package_dirs(bundled_dir("plugins"), depth=1):
        specs.extend(read_behavior_package(folder, PluginSource.BUNDLED))
    return specs


def entry_point_plugins() -> list[PluginSpec]:
    """The plugins installed distributions declare in the ``kinema.behaviors`` entry-point group."""
    specs = []
    for entry in metadata.entry_points(group=ENTRY_POINT_GROUP):
        module, _, attribute = entry.value.partition(":")
        dist = entry.dist.name if entry.dist is not None else module.split(".")[0]
        specs.append(
            PluginSpec(
                entry.name, PluginSource.ENTRY_POINT, module.strip(), dist, None, attribute.strip() or None
            )
        )
    return specs


def workspace_plugins(workspace: Path) -> tuple[list[PluginSpec], list[KinemaError]]:
    """The behavior packages of ``workspace`` (found as the config layer finds packages) and read errors."""
    from kinema.config import Workspace

    try:
        packages = Workspace.discover(workspace).packages.values()
    except KinemaError as error:
        return [], [error]
    specs: list[PluginSpec] = []
    errors: list[KinemaError] = []
    for package in sorted(packages, key=lambda p: str(p.path)):
        if package.origin != "workspace" or not (package.path / "pyproject.toml").is_file():
            continue
        try:
            specs.extend(read_behavior_package(package.path, PluginSource.WORKSPACE))
        except PluginError as error:
            errors.append(error)
    return specs, errors


def available_plugins(workspace: Path | None = None) -> tuple[dict[str, PluginSpec], list[KinemaError]]:
    """Every plugin that could be activated, by loader name (workspace > entry points > bundled)."""
    catalog: dict[str, PluginSpec] = {}
    for spec in bundled_plugins():
        catalog[spec.name] = spec
    for spec in entry_point_plugins():
        catalog[spec.name] = spec
    errors: list[KinemaError] = []
    if workspace is not None:
        specs, errors = workspace_plugins(workspace)
        for spec in specs:
            catalog[spec.name] = spec
    return catalog, errors


@dataclass(frozen=True)
class LoaderSelection:
    """The plugins a list of loader names activates, and the names that activate nothing."""

    plugins: tuple[PluginSpec, ...]
    warnings: tuple[str, ...]
    errors: tuple[PluginError, ...]


def select_loaders(loader_names: Iterable[str], catalog: Mapping[str, PluginSpec]) -> LoaderSelection:
    """Map a config's ``behavior_loader_plugins`` names to plugins.

    MoveIt Pro loaders that Kinema has no equivalent for (e.g. ``VisionBehaviorsLoader``) are warnings,
    so a real MoveIt Pro config still loads; any other unknown name is an error listing the valid ones.
    """
    chosen: dict[str, PluginSpec] = {}
    warnings: list[str] = []
    errors: list[PluginError] = []
    for requested in loader_names:
        name = LOADER_ALIASES.get(requested, requested)
        spec = catalog.get(name)
        if spec is not None:
            chosen.setdefault(spec.name, spec)
        elif requested.startswith(_MOVEIT_PREFIXES):
            warnings.append(
                f"behavior loader '{requested}' is a MoveIt Pro loader Kinema does not provide; "
                "objectives that use its behaviors will not validate"
            )
        else:
            valid = list(catalog) + list(LOADER_ALIASES)
            errors.append(
                PluginError(f"unknown behavior loader '{requested}'; {did_you_mean(requested, valid)}")
            )
    return LoaderSelection(tuple(chosen.values()), tuple(warnings), tuple(errors))
