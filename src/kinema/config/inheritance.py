"""Resolving a config package with its ``based_on_package`` chain into one config, with provenance.

The chain is followed from the named package to its root and merged root-first, child over parent:

* mappings merge recursively and the child wins on a conflict;
* lists are replaced as a whole (``controllers_active_at_startup``, ``urdf_params``, ...);
* ``objectives.behavior_loader_plugins`` is the union across the chain: every loader key of every
  package is kept, and when a child repeats a key its entries are added after the parent's (a loader
  is never dropped by a child, as MoveIt Pro's backend unions them);
* ``objectives.objective_library_paths`` merges by key (it is a mapping), so a child adds a library
  under a new key or replaces one entry by reusing its key;
* a reference (``{package, path}`` / ``{package_name, relative_path}``, e.g. ``waypoints_file``) is
  one value: a child's reference replaces the parent's.

Every merged leaf remembers the package that set it: ``provenance`` maps its dotted key path
(``hardware.robot_description.urdf``; elements of a unioned list as ``...core[2]``) to a package name.
After merging, the required keys (see :data:`kinema.config.schema.REQUIRED`) must be present and every
file or folder Kinema will use must exist.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Hashable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from kinema.config.refs import PackageRef, as_ref, is_ref
from kinema.config.schema import REQUIRED, SCHEMA, Field, dotted, is_unknown_key_notice, validate_document
from kinema.config.workspace import Package, Workspace
from kinema.config.yamlsource import YamlDocument, load_yaml_file
from kinema.errors import ConfigError, SourceLocation, did_you_mean

#: config.yaml files are a few kB; anything this large is a mistake, not a config.
MAX_CONFIG_BYTES = 2 * 1024 * 1024
_UNION_PATH: tuple[str, ...] = ("objectives", "behavior_loader_plugins")

KeyPath = tuple[Hashable, ...]


@dataclass
class ConfigSource:
    """One package's own config.yaml, parsed and checked against the schema."""

    package: Package
    document: YamlDocument
    notices: list[str] = field(default_factory=list)

    @property
    def data(self) -> dict[str, Any]:
        """The file's data (a mapping; an empty file is an empty mapping)."""
        return self.document.data  # type: ignore[no-any-return]

    @property
    def based_on(self) -> str | None:
        """The parent package name, or None for a root config."""
        value = self.data.get("based_on_package")
        return value if isinstance(value, str) and value else None


def load_config_source(package: Package) -> ConfigSource:
    """Read and validate ``package``'s config/config.yaml.

    Raises:
        ConfigError: unreadable, too large, not UTF-8, invalid YAML, not a mapping, or a wrong type.
    """
    document = load_yaml_file(package.config_file, max_bytes=MAX_CONFIG_BYTES)
    if document.data is None:
        document.data = {}
    if not isinstance(document.data, dict):
        raise ConfigError(
            "config.yaml must be a mapping of keys (hardware:, objectives:, ...), not a "
            f"{type(document.data).__name__}",
            location=document.location(()),
        )
    notices = validate_document(document, package.name)
    return ConfigSource(package=package, document=document, notices=notices)


@dataclass(frozen=True)
class LibraryPath:
    """One entry of the merged ``objectives.objective_library_paths``.

    Attributes:
        key: the entry's key in config.yaml (``sim_objectives``).
        path: the resolved folder.
        package: the package that owns the folder (the reference's package).
        declared_by: the config package whose config.yaml set the entry.
    """

    key: str
    path: Path
    package: str
    declared_by: str


@dataclass
class ResolvedConfig:
    """A config package merged with its whole inheritance chain.

    Attributes:
        name: the config package that was resolved.
        workspace: the workspace it was resolved in.
        chain: package names, root first, ending with ``name``.
        sources: each chain package's own config.yaml.
        data: the merged config, shaped like config.yaml.
        provenance: dotted key path of each merged leaf -> package that set it.
        notices: things worth saying in verbose mode (overlays, unused keys).
        warnings: things worth saying always: keys no schema knows (typos, most of the time).
    """

    name: str
    workspace: Workspace
    chain: list[str]
    sources: dict[str, ConfigSource]
    data: dict[str, Any]
    provenance: dict[str, str]
    notices: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    _origins: dict[KeyPath, str] = field(default_factory=dict, repr=False)

    @property
    def package(self) -> Package:
        """The resolved (most-derived) config package."""
        return self.sources[self.name].package

    @property
    def chain_packages(self) -> list[Package]:
        """The chain as packages, root first."""
        return [self.sources[name].package for name in self.chain]

    def package_dir(self, name: str) -> Path:
        """The folder of package ``name`` (any package the workspace sees)."""
        return self.workspace.package(name).path

    def get(self, key_path: str | KeyPath, default: Any = None) -> Any:
        """Return the merged value at a dotted key path (``"hardware.robot_description.urdf"``)."""
        value: Any = self.data
        for part in _split(key_path):
            if isinstance(value, dict) and part in value:
                value = value[part]
            elif isinstance(value, list) and isinstance(part, int) and -len(value) <= part < len(value):
                value = value[part]
            else:
                return default
        return value

    def origin_of(self, key_path: str | KeyPath) -> str | None:
        """The package that set the value at ``key_path`` (for a mapping: the most-derived one that set
        anything inside it), or None when the key is not set."""
        path = _split(key_path)
        for length in range(len(path), 0, -1):
            found = self._origins.get(path[:length])
            if found is not None:
                return found
        below = [pkg for key, pkg in self._origins.items() if key[: len(path)] == path]
        if not below:
            return None
        return max(below, key=self.chain.index)

    def location_of(self, key_path: str | KeyPath) -> SourceLocation:
        """``file:line`` where the value at ``key_path`` was set (the config's own file when unset)."""
        path = _split(key_path)
        package = self.origin_of(path) or self.name
        return self.sources[package].document.location(path)

    def resolve_file(self, ref: Any, *, kind: str = "any") -> Path:
        """Resolve a reference to an existing path.

        Args:
            ref: a ``{package, path}`` / ``{package_name, relative_path}`` mapping, a :class:`PackageRef`,
                or a dotted key path of the merged config that holds a reference.
            kind: ``"file"`` or ``"dir"`` to also check what the path is; ``"any"`` accepts both.

        Raises:
            ConfigError: not a reference, unknown package, or nothing at the path; with file:line when
                ``ref`` was a key path.
        """
        location: SourceLocation | None = None
        label = "the reference"
        if isinstance(ref, (str, tuple)):
            key_path = _split(ref)
            label = dotted(key_path)
            location = self.location_of(key_path)
            value = self.get(key_path)
            if value is None:
                raise ConfigError(
                    f"{label} is not set in config {self.name!r} (chain {' → '.join(self.chain)})"
                )
            ref = value
        package_ref = ref if isinstance(ref, PackageRef) else as_ref(ref)
        if package_ref is None:
            raise ConfigError(
                f"{label} is not a reference {{package, path}} or {{package_name, relative_path}}",
                location=location,
            )
        return _resolve_ref(self.workspace, package_ref, kind, label, location)

    def optional_file(self, key_path: str) -> Path | None:
        """Resolve the reference at ``key_path``, or return None when the key is not set."""
        return None if self.get(key_path) is None else self.resolve_file(key_path, kind="file")

    @property
    def urdf_path(self) -> Path:
        """The robot's URDF (``hardware.robot_description.urdf``)."""
        return self.resolve_file("hardware.robot_description.urdf", kind="file")

    @property
    def srdf_path(self) -> Path:
        """The robot's SRDF (``hardware.robot_description.srdf``)."""
        return self.resolve_file("hardware.robot_description.srdf", kind="file")

    @property
    def urdf_params(self) -> dict[str, str]:
        """MoveIt Pro's xacro arguments (``hardware.robot_description.urdf_params``, a list of one-key
        mappings), as ``{name: value}`` strings (``true``/``false`` for booleans, as xacro reads them)."""
        params: dict[str, str] = {}
        for item in self.get("hardware.robot_description.urdf_params") or []:
            if isinstance(item, dict):
                for key, value in item.items():
                    text = str(value).lower() if isinstance(value, bool) else str(value)
                    params[str(key)] = text
        return params

    @property
    def mujoco_model_path(self) -> Path | None:
        """The MuJoCo scene, or None for a config without one.

        ``hardware.simulation.mujoco_model`` (a file reference) when set; else MoveIt Pro's xacro argument
        ``urdf_params: - mujoco_model: PATH``, a path inside package ``mujoco_model_package`` (another
        urdf_params entry) or, without it, inside the package that set ``urdf_params``.

        Raises:
            ConfigError: the file named is not there.
        """
        if self.get("hardware.simulation.mujoco_model") is not None:
            return self.optional_file("hardware.simulation.mujoco_model")
        params = self.urdf_params
        if "mujoco_model" not in params:
            return None
        key = ("hardware", "robot_description", "urdf_params")
        package = params.get("mujoco_model_package") or self.origin_of(key) or self.name
        return self.resolve_file({"package": package, "path": params["mujoco_model"]}, kind="file")

    @property
    def mujoco_keyframe(self) -> str | None:
        """The keyframe the simulation starts from and resets to: ``hardware.simulation.mujoco_keyframe``,
        else MoveIt Pro's ``urdf_params: - mujoco_keyframe: NAME``; None for the model's own state."""
        value = self.get("hardware.simulation.mujoco_keyframe") or self.urdf_params.get("mujoco_keyframe")
        return str(value) if value else None

    @property
    def joint_limits_path(self) -> Path | None:
        """The joint limits YAML (``moveit_params.joint_limits``), or None when not set."""
        return self.optional_file("moveit_params.joint_limits")

    @property
    def waypoints_path(self) -> Path | None:
        """The waypoints file (``objectives.waypoints_file``), or None when not set."""
        return self.optional_file("objectives.waypoints_file")

    @property
    def behavior_loader_plugins(self) -> dict[str, list[str]]:
        """The unioned ``objectives.behavior_loader_plugins``: loader key -> loader names."""
        value = self.get(_UNION_PATH) or {}
        return {str(key): list(names or []) for key, names in value.items()}

    @property
    def objective_library_paths(self) -> list[LibraryPath]:
        """The merged ``objectives.objective_library_paths``, resolved, in declaration order."""
        entries = self.get(("objectives", "objective_library_paths")) or {}
        out = []
        for key in entries:
            path = self.resolve_file(("objectives", "objective_library_paths", key), kind="dir")
            ref = as_ref(entries[key])
            assert ref is not None
            declared_by = self.origin_of(("objectives", "objective_library_paths", key)) or self.name
            out.append(LibraryPath(str(key), path, self.workspace.package(ref.package).name, declared_by))
        return out

    def to_json(self, *, provenance: bool = False) -> dict[str, Any]:
        """The merged config as a JSON-ready mapping; with ``provenance``, ``{"config", "chain",
        "provenance"}``."""
        if not provenance:
            return self.data
        return {"config": self.data, "chain": self.chain, "provenance": self.provenance}


def _split(key_path: str | KeyPath) -> KeyPath:
    if not isinstance(key_path, str):
        return tuple(key_path)
    parts: list[Hashable] = []
    for piece in key_path.split("."):
        name, _, rest = piece.partition("[")
        if name:
            parts.append(name)
        while rest:
            index, _, rest = rest.partition("]")
            parts.append(int(index))
            rest = rest.removeprefix("[")
    return tuple(parts)


def _resolve_ref(
    workspace: Workspace, ref: PackageRef, kind: str, label: str, location: SourceLocation | None
) -> Path:
    if not workspace.has_package(ref.package):
        raise ConfigError(
            f"{label} refers to package {ref.package!r}, which is not in {workspace.describe()}; "
            f"{did_you_mean(ref.package, workspace.packages)}",
            location=location,
        )
    package = workspace.package(ref.package)
    path = package.resolve_relative(ref.path)
    # Lexically (symlinks a package holds are its own business): '..' and absolute paths leave it.
    inside = Path(os.path.normpath(path)).is_relative_to(os.path.normpath(package.path))
    if not inside:
        raise ConfigError(
            f"{label}: {ref} leaves package {package.name!r} ({os.path.normpath(path)} is outside "
            f"{package.path}); a reference names a file inside its package",
            location=location,
        )
    if package.kind == "objectives" and path == package.path:
        return path  # the core library is always there, even before anything has been put into it
    if not path.exists():
        raise ConfigError(f"{label}: {ref} does not exist (looked for {path})", location=location)
    if kind == "file" and not path.is_file():
        raise ConfigError(f"{label}: {ref} is a folder, a file is expected ({path})", location=location)
    if kind == "dir" and not path.is_dir():
        raise ConfigError(f"{label}: {ref} is a file, a folder is expected ({path})", location=location)
    return path


def resolve_chain(name: str, workspace: Workspace) -> list[ConfigSource]:
    """Load ``name`` and its ancestors; return their sources root first.

    Raises:
        ConfigError: unknown package, a package that is not a config package, a cycle (the message
            prints it) or a missing parent (the message lists the known config packages).
    """
    config_names = [p.name for p in workspace.config_packages(include_hidden=True)]
    if not workspace.has_package(name):
        raise ConfigError(
            f"no config package named {name!r} in {workspace.describe()}; {did_you_mean(name, config_names)}"
        )
    sources: list[ConfigSource] = []
    seen: dict[str, int] = {}
    current: str | None = name
    child: ConfigSource | None = None
    while current is not None:
        if not workspace.has_package(current):
            assert child is not None
            raise ConfigError(
                f"config package {child.package.name!r} is based on {current!r}, "
                f"which is not a known package; "
                f"{did_you_mean(current, config_names)}",
                location=child.document.location(("based_on_package",)),
            )
        package = workspace.package(current)
        if package.name in seen:
            cycle = [s.package.name for s in sources[seen[package.name] :]] + [package.name]
            assert child is not None
            raise ConfigError(
                f"inheritance cycle: {' → '.join(cycle)}",
                location=child.document.location(("based_on_package",)),
            )
        if not package.is_config:
            where = child.document.location(("based_on_package",)) if child is not None else None
            raise ConfigError(
                f"package {package.name!r} ({package.path}) is not a config package "
                "(it has no config/config.yaml); "
                f"config packages: {', '.join(config_names) or 'none'}",
                location=where,
            )
        source = load_config_source(package)
        seen[package.name] = len(sources)
        sources.append(source)
        child = source
        current = source.based_on
    sources.reverse()
    return sources


def merge_layers(layers: list[tuple[str, dict[str, Any]]]) -> tuple[dict[str, Any], dict[KeyPath, str]]:
    """Merge config mappings root first with the rules in the module docstring.

    Args:
        layers: ``(package name, config data)`` pairs, root first.

    Returns:
        The merged data and the package that set each leaf, by key path.
    """
    merged: dict[str, Any] = {}
    origins: dict[KeyPath, str] = {}
    for package, layer in layers:
        _merge_into(merged, layer, (), package, origins)
    if "based_on_package" in merged:  # keep it first, where config.yaml files put it
        merged = {"based_on_package": merged.pop("based_on_package"), **merged}
    return merged, origins


def _merge_into(
    target: dict[Any, Any], source: dict[Any, Any], path: KeyPath, package: str, origins: dict[KeyPath, str]
) -> None:
    for key, value in source.items():
        key_path = (*path, key)
        existing = target.get(key)
        is_map = isinstance(value, dict) and not is_ref(value)
        if path == _UNION_PATH and isinstance(value, list):
            if not isinstance(existing, list):
                if key in target:
                    _drop(origins, key_path)
                existing = target[key] = []
            for item in value:
                if item not in existing:
                    origins[(*key_path, len(existing))] = package
                    existing.append(copy.deepcopy(item))
            continue
        if is_map and isinstance(existing, dict) and not is_ref(existing):
            _merge_into(existing, value, key_path, package, origins)
            continue
        if key in target:
            _drop(origins, key_path)
        if is_map:
            target[key] = {}
            if value:
                _merge_into(target[key], value, key_path, package, origins)
            else:
                origins[key_path] = package
        else:
            target[key] = copy.deepcopy(value)
            origins[key_path] = package


def _drop(origins: dict[KeyPath, str], prefix: KeyPath) -> None:
    size = len(prefix)
    for key in [key for key in origins if key[:size] == prefix]:
        del origins[key]


def resolve_config(
    name: str, workspace: Workspace | None = None, *, check_files: bool = True
) -> ResolvedConfig:
    """Resolve config package ``name`` with its inheritance chain.

    Args:
        name: the config package (an alias of a package is accepted too).
        workspace: where to look; default: the active workspace.
        check_files: check that every file and folder Kinema uses exists (URDF, SRDF, MuJoCo model,
            joint limits, objective libraries, waypoints file).

    Raises:
        ConfigError: any problem of the chain, a schema error, a missing required key, a reference to an
            unknown package or a missing file; the message carries file:line and the alternatives.
    """
    workspace = workspace if workspace is not None else Workspace.discover()
    sources = resolve_chain(name, workspace)
    chain = [source.package.name for source in sources]
    said = [*workspace.notices, *(n for source in sources for n in source.notices)]
    data, origins = merge_layers([(source.package.name, source.data) for source in sources])
    resolved = ResolvedConfig(
        name=chain[-1],
        workspace=workspace,
        chain=chain,
        sources={source.package.name: source for source in sources},
        data=data,
        provenance={dotted(key): package for key, package in origins.items()},
        notices=[n for n in said if not is_unknown_key_notice(n)],
        warnings=[n for n in said if is_unknown_key_notice(n)],
        _origins=origins,
    )
    _check_required(resolved)
    if check_files:
        for key_path, spec in _used_refs(resolved.data, SCHEMA, ()):
            resolved.resolve_file(key_path, kind=spec.kind)
    return resolved


def _check_required(resolved: ResolvedConfig) -> None:
    for key_path in REQUIRED:
        if resolved.get(key_path) is None:
            own = resolved.sources[resolved.name]
            hints = resolved.warnings
            hint = f" (note: {hints[0]})" if hints else ""
            raise ConfigError(
                f"config {resolved.name!r} does not set {dotted(key_path)}, which is required, "
                "and neither does any "
                f"package it is based on (chain {' → '.join(resolved.chain)}){hint}",
                location=own.document.location(key_path),
            )


def _used_refs(value: Any, spec: Field, path: KeyPath) -> Iterator[tuple[KeyPath, Field]]:
    """Yield the key paths of references Kinema uses (``used`` file/dir fields) in merged data."""
    if spec.kind in ("file", "dir"):
        if spec.used and value is not None:
            yield path, spec
        return
    if not spec.used or not isinstance(value, dict):
        return
    if spec.kind == "map":
        for key, child in spec.keys.items():
            if key in value:
                yield from _used_refs(value[key], child, (*path, key))
    elif spec.kind == "map_of" and spec.item is not None:
        for key in value:
            yield from _used_refs(value[key], spec.item, (*path, key))
