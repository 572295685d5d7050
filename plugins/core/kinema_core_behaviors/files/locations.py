"""Where the files behaviors read and write live, resolved as MoveIt Pro resolves them.

- A relative path names a file in the config package's objectives folder: reads look in every
  objective library of the config (most-derived package first), writes go to the most-derived package's
  own library. A relative path may not climb out of that folder (``../``): a save never lands outside
  the folder it was meant for.
- A config bundled with Kinema (lab_sim) is never written into: its saves go to
  ``<user data>/kinema/files/<config>/`` (as its waypoints go beside it, see
  :mod:`kinema.config.waypoint_location`), which reads look in first. Kinema's installation (or a
  checkout of it) stays as it was.
- ``~/user_ws/src/<package>/objectives/<rest>`` (MoveIt Pro's workspace path, common in its objectives)
  is ``<rest>`` relative to the objectives folder as above, so a copy of the objective in another config
  reads and writes its own config's files, never an installed package's. Other
  ``~/user_ws/src/<package>/<rest>`` paths are ``<rest>`` inside that package's folder.
- With a ``package_name``, a relative path is inside that package's folder.
- Any other absolute path (``~/file``, a folder of the workspace) is used as written.

Whatever form, the file must then pass :func:`kinema.behaviors.file_access.check_file_access`: inside the
workspace, the config packages or Kinema's data folder (a file written: also directly in the system's
temporary folder), never the security folder (``..`` and symlinks resolved first). A refusal names the
rule.
Saves need a library folder of the config's own package; without a config (offline runs, ``kinema tree
run``) relative paths resolve against the working directory.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from kinema.behaviors.file_access import FileAccessError, check_file_access
from kinema.config.robot_files import is_lfs_pointer

from ..messages.ports import PortValueError, port_error

_USER_WS = re.compile(r"^~/user_ws/src/([^/]+)/(.*)$")
# What the file ports say about relative names (one wording for every file behavior).
RELATIVE_READ = (
    "relative paths are in the config's objectives folders (for a config bundled with Kinema, "
    "$XDG_DATA_HOME/kinema/files/<config>/ first)"
)
RELATIVE_WRITE = (
    "relative names are in the config's objectives folder (for a config bundled with Kinema, "
    "$XDG_DATA_HOME/kinema/files/<config>/)"
)


def objective_folders(node: Any) -> list[Path]:
    """The config's objective library folders, its own package's first (the working directory offline)."""
    resolved = node.context.config
    if resolved is None:
        return [Path.cwd()]
    saved = [user_files_dir(resolved.name)] if _is_bundled(resolved) else []
    chain = list(resolved.chain)
    ranked = sorted(
        resolved.objective_library_paths,
        key=lambda lib: chain.index(lib.package) if lib.package in chain else -1,
        reverse=True,
    )
    return list(dict.fromkeys([*saved, *(Path(lib.path) for lib in ranked)])) or [Path.cwd()]


def user_files_dir(config_name: str) -> Path:
    """Where files saved by the objectives of bundled config ``config_name`` go (not created here)."""
    import platformdirs

    return platformdirs.user_data_path("kinema") / "files" / config_name


def _is_bundled(resolved: Any) -> bool:
    return getattr(resolved.package, "origin", "") == "bundled"


def save_folder(node: Any, port: str) -> Path:
    """Where relative saves go: the first objective library of the config's own package (for a bundled
    config, :func:`user_files_dir`).

    Raises:
        PortValueError: the config has no library folder of its own (saving into an inherited or
            installed package is refused).
    """
    resolved = node.context.config
    if resolved is None:
        return Path.cwd()
    if _is_bundled(resolved):
        folder = user_files_dir(resolved.name)
        folder.mkdir(parents=True, exist_ok=True)
        return folder
    for lib in resolved.objective_library_paths:
        if lib.package == resolved.name:
            return Path(lib.path)
    raise port_error(
        node,
        port,
        f"names a file to save, but config {resolved.name!r} has no objective library of its own",
        f"add an objective_library_paths entry with package_name: {resolved.name}",
    )


def _package_dir(node: Any, package: str, port: str) -> Path:
    resolved = node.context.config
    if resolved is None:
        raise port_error(node, port, f"names package {package!r}, but no config is loaded", "")
    try:
        return Path(resolved.package_dir(package))
    except Exception as error:  # the workspace's own lookup error names the known packages
        raise port_error(node, port, f"names unknown package {package!r}", str(error)) from None


def _in_chain_objectives(node: Any, package: str, rest: str) -> str | None:
    """``rest`` relative to the objectives folder when it is ``objectives/...`` of a package of the config's
    chain (``package://lab_sim/objectives/x`` in a copy of lab_sim's objectives means the copy's ``x``)."""
    resolved = node.context.config
    if resolved is not None and package in resolved.chain and rest.startswith("objectives/"):
        return rest[len("objectives/") :]
    return None


def _explicit(node: Any, port: str, text: str, package: str = "") -> Path | None:
    """The path for forms that name their folder themselves; None for a path relative to the objectives."""
    match = _USER_WS.match(text)
    if match is not None:
        inside = match.group(2)
        if inside.startswith("objectives/"):
            return None
        try:
            return _package_dir(node, match.group(1), port) / inside
        except PortValueError:
            return Path(text).expanduser()
    if text.startswith("~") or Path(text).is_absolute():
        return Path(text).expanduser()
    if package:
        if _in_chain_objectives(node, package, text) is not None:
            return None
        return _package_dir(node, package, port) / text
    return None


def _relative(text: str) -> str:
    """The part of ``text`` relative to the objectives folder."""
    match = _USER_WS.match(text)
    if match is not None:
        return match.group(2)[len("objectives/") :]
    return text[len("objectives/") :] if text.startswith("objectives/") else text


def split_package_uri(text: str) -> tuple[str, str]:
    """``("pkg", "path")`` of ``package://pkg/path``; ``("", text)`` for anything else."""
    if text.startswith("package://"):
        package, _, rest = text[len("package://") :].partition("/")
        return package, rest
    return "", text


def _inside(folder: Path, relative: str, node: Any, port: str) -> Path:
    path = (folder / relative).resolve()
    if not path.is_relative_to(folder.resolve()):
        raise port_error(
            node,
            port,
            f"= {relative!r} leaves the folder {folder}",
            "give a path inside the objectives folder",
        )
    return path


def _allowed(node: Any, port: str, text: str, path: Path, *, writing: bool = False) -> Path:
    """``path`` resolved, or a PortValueError naming the rule that refuses it."""
    try:
        return check_file_access(path, node.context.config, writing=writing)
    except FileAccessError as error:
        raise port_error(node, port, f"= {text!r}: {error}") from None


def with_suffix(text: str, suffix: str) -> str:
    """``text`` with ``suffix`` appended unless it already ends with it (``.yaml``/``.yml`` both count)."""
    lowered = text.lower()
    if suffix == ".yaml" and lowered.endswith((".yaml", ".yml")):
        return text
    return text if lowered.endswith(suffix) else text + suffix


def file_to_read(node: Any, port: str, text: str, package: str = "", *, lfs_pointer_ok: bool = False) -> Path:
    """The existing file ``text`` names (a Git LFS pointer file only with ``lfs_pointer_ok``: a behavior
    that only shows the file may say so and go on).

    Raises:
        PortValueError: empty, or no such file (naming every folder looked in).
    """
    if not text.strip():
        raise port_error(node, port, "is empty", "give a file name, e.g. my_poses.yaml")
    explicit = _explicit(node, port, text, package)
    if explicit is not None:
        candidates = [explicit]
    else:
        names = list(
            dict.fromkeys([_relative(text), text] if not _USER_WS.match(text) else [_relative(text)])
        )
        candidates = [
            _inside(folder, name, node, port) for folder in objective_folders(node) for name in names
        ]
    for candidate in candidates:
        allowed = _allowed(node, port, text, candidate)
        if allowed.is_file():
            if not lfs_pointer_ok and is_lfs_pointer(allowed):
                # A clone without `git lfs pull` (MoveIt Pro's example images and meshes): not the file.
                raise port_error(
                    node,
                    port,
                    f"= {text!r}: {allowed} is a Git LFS pointer file, not the file itself",
                    "run `git lfs pull` in its repository",
                )
            return allowed
    looked = ", ".join(dict.fromkeys(str(c.parent) for c in candidates))
    raise port_error(node, port, f"= {text!r}: no such file", f"looked in {looked}")


def file_to_write(node: Any, port: str, text: str, suffix: str = "") -> Path:
    """Where a save of ``text`` goes (with ``suffix`` added when missing); its folder must exist.

    Raises:
        PortValueError: empty, climbing out of the objectives folder, or the folder does not exist.
    """
    if not text.strip():
        raise port_error(node, port, "is empty", "give a file name, e.g. my_trajectory")
    text = with_suffix(text, suffix) if suffix else text
    explicit = _explicit(node, port, text)
    path = explicit if explicit is not None else _inside(save_folder(node, port), _relative(text), node, port)
    path = _allowed(node, port, text, path, writing=True)
    if not path.parent.is_dir():
        raise port_error(node, port, f"= {text!r}: the folder {path.parent} does not exist", "")
    return path
