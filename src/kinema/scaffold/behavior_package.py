"""``kinema new behavior``: a behavior package, or one more behavior in one, from a template.

A new package gets ``pyproject.toml`` (with its ``kinema.behaviors`` loader entry point), the behavior
module, the registration in ``__init__.py``, an example objective and a passing test. With an existing
package, the behavior module, its test and its example objective are added and the behavior is
registered in the package's ``__init__.py``. Every name is checked before anything is written.

When the active config package lives in the same workspace, its ``config/config.yaml`` gains the
package's loader under ``objectives.behavior_loader_plugins`` and the package's ``objectives/`` folder
under ``objectives.objective_library_paths`` (comments and layout kept), so the behavior and its example
objective are usable at once.
"""

from __future__ import annotations

import re
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from kinema.config.workspace import Package, Workspace, select_workspace_hint
from kinema.errors import ConfigError, ScaffoldError, did_you_mean
from kinema.scaffold.generate import generate
from kinema.scaffold.names import BEHAVIOR_TYPES, module_name_problem, package_name_problem

TEMPLATE = "behavior_package"


@dataclass
class NewBehavior:
    """What ``new_behavior`` did.

    Attributes:
        behavior_id: the registered ID (CamelCase of the name).
        package: the behavior package name.
        package_dir: its folder.
        loader_name: the loader name configs list in ``behavior_loader_plugins``.
        created_package: True for a new package, False when a behavior was added to an existing one.
        files: the files written (or changed) in the package.
        config_file: the config.yaml that was updated, or None.
        config_changes: what was added to it, one line each.
    """

    behavior_id: str
    package: str
    package_dir: Path
    loader_name: str
    created_package: bool
    files: list[Path] = field(default_factory=list)
    config_file: Path | None = None
    config_changes: list[str] = field(default_factory=list)


def behavior_id_for(name: str) -> str:
    """The behavior ID (and class name) for a snake_case name: ``my_service_client`` → ``MyServiceClient``."""
    return "".join(part[:1].upper() + part[1:] for part in name.split("_") if part)


def check_behavior_name(name: str) -> None:
    """Raise ScaffoldError unless ``name`` is a snake_case name usable as module and package name."""
    problem = package_name_problem(name)
    if problem is not None:
        raise ScaffoldError(
            f"{name!r} is not a valid behavior name: {problem.replace('my_robot_config', 'my_behavior')}"
        )
    clash = module_name_problem(name)
    if clash is not None:
        raise ScaffoldError(f"{clash}; choose another behavior name, e.g. my_{name}")


def check_behavior_type(behavior_type: str) -> None:
    """Raise ScaffoldError unless ``behavior_type`` is one of :data:`BEHAVIOR_TYPES`."""
    if behavior_type not in BEHAVIOR_TYPES:
        raise ScaffoldError(
            f"unknown behavior type {behavior_type!r}; {did_you_mean(behavior_type, BEHAVIOR_TYPES)}"
        )


def new_behavior(
    name: str,
    behavior_type: str,
    *,
    workspace: Workspace,
    package: str | None = None,
    config: str | None = None,
    description: str | None = None,
) -> NewBehavior:
    """Create behavior ``name`` of ``behavior_type`` in a new package, or in ``package``.

    Args:
        name: snake_case behavior name; the module is ``<name>.py``, the ID is CamelCase(name).
        behavior_type: one of :data:`BEHAVIOR_TYPES`.
        workspace: the workspace (its ``src/`` receives new packages).
        package: an existing behavior package of the workspace to add the behavior to; None creates a
            package named ``name``.
        config: the active config package; when it lives in ``workspace`` its config.yaml is updated.
        description: the new package's description.

    Raises:
        ScaffoldError: invalid name or type, no workspace, a taken package name or module, an unknown
            package (with the valid ones); nothing is written then.
    """
    from kinema.plugins.discovery import PluginSource, default_loader_name, read_behavior_package

    check_behavior_name(name)
    check_behavior_type(behavior_type)
    if workspace.root is None:
        raise ScaffoldError(
            f"no workspace is selected, so there is no src/ to create the behavior package in; "
            f"{select_workspace_hint()}"
        )
    behavior_id = behavior_id_for(name)
    context = {"behavior_name": name, "behavior_id": behavior_id, "behavior_type": behavior_type}
    config_package = _workspace_config(workspace, config)
    if config:
        _check_id_is_free(behavior_id, workspace, config)

    if package is None:
        if workspace.has_package(name):
            existing = workspace.package(name)
            raise ScaffoldError(
                f"a package named {name!r} already exists ({existing.path}); add the behavior to it with "
                f"--package {name}, or choose another name"
            )
        loader = default_loader_name(name)
        values = {
            **context,
            "package_name": name,
            "loader_name": loader,
            "description": description or f"Kinema behaviors of {name}",
        }
        package_dir = generate(TEMPLATE, workspace.root / "src", values)
        files = sorted(path for path in package_dir.rglob("*") if path.is_file())
        result = NewBehavior(behavior_id, name, package_dir, loader, True, files)
    else:
        package_dir = _behavior_package_dir(workspace, package)
        specs = read_behavior_package(package_dir, PluginSource.WORKSPACE)
        loader = specs[0].name
        module_dir = package_dir / specs[0].module.split(".")[0]
        targets = {
            "module": module_dir / f"{name}.py",
            "test": package_dir / "tests" / f"test_{name}.py",
            "objective": package_dir / "objectives" / f"{name}.xml",
        }
        taken = [path for path in targets.values() if path.exists()]
        if taken:
            raise ScaffoldError(f"{taken[0]} already exists; choose another behavior name")
        init = module_dir / "__init__.py"
        new_init = _register_in_init(init.read_text(encoding="utf-8"), name, behavior_id, init)
        values = {**context, "package_name": module_dir.name, "loader_name": loader}
        with tempfile.TemporaryDirectory(prefix="kinema-new-behavior-") as scratch:
            baked = generate(TEMPLATE, scratch, values)
            sources = {
                "module": baked / module_dir.name / f"{name}.py",
                "test": baked / "tests" / f"test_{name}.py",
                "objective": baked / "objectives" / f"{name}.xml",
            }
            for key, target in targets.items():
                target.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(sources[key], target)
        from kinema.config.atomic_write import atomic_write_text

        atomic_write_text(init, new_init)
        written = [*targets.values(), init]
        readme = package_dir / "README.md"
        row = f"| `{behavior_id}` | {context['behavior_type']} | `{module_dir.name}/{name}.py` |"
        if _add_table_row(readme, row):
            written.append(readme)
        result = NewBehavior(behavior_id, package, package_dir, loader, False, written)

    if config_package is not None:
        result.config_file = config_package.config_file
        result.config_changes = add_to_config(
            config_package.config_file,
            result.package,
            loader,
            objectives=(result.package_dir / "objectives").is_dir(),
        )
    return result


def _add_table_row(readme: Path, row: str) -> bool:
    """Add ``row`` after the last row of the template README's behavior table; False (nothing written)
    when there is no README or its table is gone (the user rewrote it)."""
    from kinema.config.atomic_write import atomic_write_text

    try:
        lines = readme.read_text(encoding="utf-8").splitlines(keepends=True)
    except OSError:
        return False
    title = "| Behavior | Type | Module |"
    header = next((i for i, line in enumerate(lines) if line.startswith(title)), None)
    if header is None:
        return False
    end = header + 1
    while end < len(lines) and lines[end].startswith("|"):
        end += 1
    lines.insert(end, row + "\n")
    atomic_write_text(readme, "".join(lines))
    return True


def _check_id_is_free(behavior_id: str, workspace: Workspace, config: str) -> None:
    """Refuse an ID that a behavior the config already loads has: the two would collide at load time."""
    from kinema.config import resolve_config
    from kinema.errors import KinemaError
    from kinema.plugins.host import BehaviorHost

    try:
        resolved = resolve_config(config, workspace, check_files=False)
    except KinemaError:
        # A config that does not resolve loads no behaviors, so nothing can collide; `kinema build`
        # reports what is wrong with it.
        return
    host = BehaviorHost.for_config(resolved)
    host.load()
    existing = host.registry.get(behavior_id)
    if existing is not None:
        raise ScaffoldError(
            f"behavior ID {behavior_id!r} is already registered by plugin '{existing.plugin}' "
            f"({existing.location}), which config {resolved.name!r} loads; choose another name"
        )


def _workspace_config(workspace: Workspace, config: str | None) -> Package | None:
    if not config or not workspace.has_package(config):
        return None
    package = workspace.package(config)
    if package.origin != "workspace" or not package.is_config:
        return None
    return package


def _behavior_package_dir(workspace: Workspace, package: str) -> Path:
    from kinema.plugins.discovery import PluginSource, read_behavior_package

    candidates = {
        p.name: p.path
        for p in workspace.packages.values()
        if p.origin == "workspace" and (p.path / "pyproject.toml").is_file()
    }
    assert workspace.root is not None  # checked by new_behavior
    behavior_packages = [
        n for n, path in candidates.items() if read_behavior_package(path, PluginSource.WORKSPACE)
    ]
    if package not in behavior_packages:
        raise ScaffoldError(
            f"no behavior package named {package!r} in {workspace.root / 'src'}; "
            f"{did_you_mean(package, behavior_packages)}"
        )
    return candidates[package]


_IMPORT = re.compile(r"^from \.\w+ import .+$")
_REGISTER = re.compile(r"^(\s+)register\(")


def _register_in_init(text: str, name: str, behavior_id: str, path: Path) -> str:
    """``text`` of a package's ``__init__.py`` with ``from .name import ID`` and ``register(ID)`` added."""
    lines = text.splitlines()
    import_line = f"from .{name} import {behavior_id}"
    imports = [i for i, line in enumerate(lines) if _IMPORT.match(line)]
    registers = [i for i, line in enumerate(lines) if _REGISTER.match(line)]
    if not imports or not registers:
        raise ScaffoldError(
            f"cannot find where {path} imports and registers its behaviors; add "
            f"'{import_line}' and 'register({behavior_id})' in its register_behaviors() yourself"
        )
    last_register = registers[-1]
    indent = _REGISTER.match(lines[last_register]).group(1)  # type: ignore[union-attr]
    lines.insert(last_register + 1, f"{indent}register({behavior_id})")
    first, last = imports[0], imports[-1]
    block = sorted({*lines[first : last + 1], import_line})
    lines[first : last + 1] = block
    return "\n".join(lines) + "\n"


def add_to_config(config_file: Path, package: str, loader: str, *, objectives: bool = True) -> list[str]:
    """Add ``loader`` (and, with ``objectives``, the package's ``objectives/`` library) to a config.yaml.

    Returns what changed, one line per change.

    The file is edited as a round trip (comments, order and quoting kept) and replaced atomically.

    Raises:
        ConfigError: the file cannot be parsed, or ``objectives`` is not a mapping.
    """
    from ruamel.yaml import YAML
    from ruamel.yaml.comments import CommentedMap, CommentedSeq
    from ruamel.yaml.error import YAMLError

    from kinema.config.atomic_write import atomic_write_text

    yaml = YAML()
    yaml.preserve_quotes = True
    yaml.indent(mapping=2, sequence=4, offset=2)
    yaml.width = 4096  # never fold a long line the file did not fold
    try:
        data = yaml.load(config_file.read_text(encoding="utf-8"))
    except YAMLError as error:
        raise ConfigError(f"{config_file}: cannot update it, it does not parse: {error}") from None
    if data is None:
        data = CommentedMap()
    section = data.get("objectives")
    if section is None:  # absent, or an empty `objectives:` key
        section = data["objectives"] = CommentedMap()
    if not isinstance(section, dict):
        raise ConfigError(f"{config_file}: 'objectives' must be a mapping to add a behavior loader to it")
    changes: list[str] = []
    loaders = section.get("behavior_loader_plugins")
    if loaders is None:
        loaders = section["behavior_loader_plugins"] = CommentedMap()
    already = any(loader in (names or []) for names in loaders.values())
    if not already:
        comment = _take_trailing_comment(loaders)
        entry = loaders.setdefault(package, CommentedSeq())
        entry.append(loader)
        _put_trailing_comment(loaders, comment)
        changes.append(f"objectives.behavior_loader_plugins.{package}: + {loader}")
    libraries = section.get("objective_library_paths")
    if libraries is None:
        libraries = section["objective_library_paths"] = CommentedMap()
    key = f"{package}_objectives"
    if objectives and key not in libraries:
        comment = _take_trailing_comment(libraries)
        libraries[key] = CommentedMap([("package_name", package), ("relative_path", "objectives")])
        _put_trailing_comment(libraries, comment)
        changes.append(f"objectives.objective_library_paths.{key}: {package}/objectives")
    if changes:
        import io

        buffer = io.StringIO()
        yaml.dump(data, buffer)
        atomic_write_text(config_file, buffer.getvalue())
    return changes


def _last_scalar_slot(node: Any) -> tuple[Any, Any] | None:
    """The mapping and key of the last scalar under ``node`` (where ruamel keeps a trailing comment)."""
    from ruamel.yaml.comments import CommentedMap

    while isinstance(node, CommentedMap) and len(node):
        key = list(node)[-1]
        child = node[key]
        if isinstance(child, CommentedMap) and len(child):
            node = child
            continue
        return node, key
    return None


def _take_trailing_comment(node: Any) -> Any:
    """Detach the comment lines that follow ``node``'s last entry (they introduce what comes after it).

    Without this, entries appended to ``node`` would land below those comment lines, as if the comments
    were about them.
    """
    slot = _last_scalar_slot(node)
    if slot is None:
        return None
    mapping, key = slot
    items = mapping.ca.items.get(key)
    if not items or len(items) < 3 or items[2] is None:
        return None
    comment, items[2] = items[2], None
    return comment


def _put_trailing_comment(node: Any, comment: Any) -> None:
    """Attach ``comment`` after ``node``'s (new) last entry."""
    if comment is None:
        return
    slot = _last_scalar_slot(node)
    if slot is None:
        return
    mapping, key = slot
    items = mapping.ca.items.setdefault(key, [None, None, None, None])
    items[2] = comment
