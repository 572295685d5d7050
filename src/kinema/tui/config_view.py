"""What the Configs screen shows about one config package, computed without any UI.

A resolved config becomes rows ``(key path, value, package that set it)`` and a package becomes a list of
its files relative to its folder, so both can be tested as data and shown in any widget.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from kinema.config import ResolvedConfig

#: A config package with more files than this is listed up to here (a workspace is not a file browser).
MAX_LISTED_FILES = 400
_SKIPPED = frozenset({"__pycache__", "build", "install", "log", "node_modules"})


@dataclass(frozen=True)
class ConfigRow:
    """One merged leaf of a config: ``hardware.robot_description.urdf = {...}`` set by ``lab_sim``."""

    key: str
    value: str
    package: str


def config_rows(resolved: ResolvedConfig) -> list[ConfigRow]:
    """The merged config's leaves in file order, each with the package that set it.

    A file reference (``{package, path}``) is one leaf, as the merge treats it.
    """
    rows: list[ConfigRow] = []
    _flatten(resolved, resolved.data, (), rows)
    return rows


def _flatten(resolved: ResolvedConfig, value: Any, path: tuple[Any, ...], rows: list[ConfigRow]) -> None:
    if isinstance(value, dict) and value and not _is_reference(value):
        for key, child in value.items():
            _flatten(resolved, child, (*path, key), rows)
        return
    key = ".".join(str(part) for part in path)
    rows.append(ConfigRow(key, _render(value), resolved.origin_of(path) or resolved.name))


def _is_reference(value: dict[Any, Any]) -> bool:
    return set(value) in ({"package", "path"}, {"package_name", "relative_path"})


def _render(value: Any) -> str:
    if isinstance(value, dict):
        if _is_reference(value):
            package = value.get("package", value.get("package_name"))
            path = value.get("path", value.get("relative_path"))
            return f"{package}: {path}"
        return "{}"
    if isinstance(value, list):
        return "[" + ", ".join(_render(item) for item in value) + "]"
    if value is None:
        return "~"
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def package_files(folder: Path, limit: int = MAX_LISTED_FILES) -> tuple[list[str], bool]:
    """The files of a package, relative to its folder, sorted; and whether the list was cut at ``limit``."""
    found: list[str] = []
    for current, folders, files in os.walk(folder):
        folders[:] = sorted(f for f in folders if not f.startswith(".") and f not in _SKIPPED)
        base = Path(current).relative_to(folder)
        for name in sorted(files):
            if name.startswith("."):
                continue
            found.append((base / name).as_posix())
            if len(found) >= limit:
                return found, True
    return found, False
