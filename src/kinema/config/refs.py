"""File and folder references in config.yaml: ``{package, path}`` and ``{package_name, relative_path}``.

MoveIt Pro names a file inside a package with a *file ref* (``package`` + ``path``) and a folder (or,
for ``waypoints_file``, a file) with a *dir ref* (``package_name`` + ``relative_path``). Kinema accepts
either shape wherever a reference is expected; what must exist at the end (a file or a folder) depends on
the key, not on the shape. A reference is always replaced as a whole when a child config overrides it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

FILE_REF_KEYS = frozenset({"package", "path"})
DIR_REF_KEYS = frozenset({"package_name", "relative_path"})


@dataclass(frozen=True)
class PackageRef:
    """A path inside a package, as written in config.yaml."""

    package: str
    path: str

    def __str__(self) -> str:
        return f"{self.package}/{self.path}"


def is_ref(value: Any) -> bool:
    """Return True when ``value`` has the shape of a file ref or a dir ref."""
    return isinstance(value, dict) and set(value) in (FILE_REF_KEYS, DIR_REF_KEYS)


def looks_like_ref(value: Any) -> bool:
    """Return True when ``value`` is a mapping that shares a key with one of the reference shapes."""
    return isinstance(value, dict) and bool(set(value) & (FILE_REF_KEYS | DIR_REF_KEYS))


def as_ref(value: Any) -> PackageRef | None:
    """Return the :class:`PackageRef` ``value`` denotes, or None when it is not a well-formed reference."""
    if not is_ref(value):
        return None
    if "package" in value:
        package, path = value["package"], value["path"]
    else:
        package, path = value["package_name"], value["relative_path"]
    if not isinstance(package, str) or not isinstance(path, str):
        return None
    return PackageRef(package, path)
