"""Which files an objective may read or write: the file rule and the security rule.

A path reaches a file behavior from an objective's XML or a parameter override, that is from whoever may
start objectives; a running objective therefore never gets more of the disk than the cell's own folders.
Whatever role asked, and whichever port carries the path:

- **the security rule**: nothing inside the security folder (``kinema security init``'s CA key, the
  router's key, the client configs) is read or written, wherever that folder is;
- **the file rule**: once ``..`` and symlinks are resolved, the file is inside the workspace, one of the
  config packages the workspace sees, or Kinema's data folder (``$XDG_DATA_HOME/kinema``); without a
  config (``kinema tree run``, tests) the working directory stands for the workspace. A file *written*
  may also lie directly in the system's temporary folder (``/tmp/inspection_image.png``, where MoveIt
  Pro's objectives save scratch images): not in a folder below it, and never read from there, so an
  objective can neither reach another program's temporary files nor read back what others left.
- **the robot rule**, for files written: never over the files that define the robot — each chain
  package's ``config/config.yaml``, the URDF, SRDF, joint limits, MuJoCo scene — nor the waypoints file
  (the agent's ``/edit_waypoints`` writes that, a grant of its own), in a workspace package or a bundled
  one. An objective that may run ad-hoc XML could otherwise rewrite the robot's joint limits.

:func:`check_file_access` is what :mod:`kinema_core_behaviors.files.locations` calls for every file
behavior; a third-party behavior that opens a file named by a port should call it too.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from kinema.errors import KinemaError

SECURITY_RULE = "security rule: objectives never read or write the security folder"
FILE_RULE = (
    "file rule: objectives read and write only inside the workspace, the config packages and Kinema's "
    "data folder, and also write files directly in the system's temporary folder"
)


ROBOT_RULE = (
    "robot rule: objectives never write over the files that define the robot (config.yaml, URDF, SRDF, "
    "joint limits, MuJoCo scene) or its waypoints file (/edit_waypoints changes waypoints)"
)


class FileAccessError(KinemaError):
    """A path an objective gave is outside what the file rule or the security rule allows."""


def security_folders() -> list[Path]:
    """Every folder that may hold the cell's keys: ``$KINEMA_SECURITY_DIR`` and the default one."""
    import platformdirs

    folders = [platformdirs.user_config_path("kinema") / "security"]
    configured = os.environ.get("KINEMA_SECURITY_DIR")
    if configured:
        folders.append(Path(configured).expanduser())
    return _unique(folders)


def allowed_folders(config: Any) -> list[Path]:
    """The folders the file rule allows for ``config`` (a ResolvedConfig, or None offline)."""
    import platformdirs

    folders = [platformdirs.user_data_path("kinema")]
    if config is None:
        folders.append(Path.cwd())
        return _unique(folders)
    workspace = config.workspace
    if workspace.root is not None:
        folders.append(Path(workspace.root))
    folders += [Path(package.path) for package in workspace.packages.values()]
    return _unique(folders)


def protected_from_writing(config: Any) -> list[Path]:
    """The files the robot rule keeps objectives from writing, for ``config`` (none offline)."""
    if config is None:
        return []
    files = [Path(package.config_file) for package in config.chain_packages]
    for name in ("urdf_path", "srdf_path", "joint_limits_path", "mujoco_model_path", "waypoints_path"):
        try:
            path = getattr(config, name)
        except KinemaError:
            continue  # a file the config names wrongly: kinema build says so
        if path is not None:
            files.append(Path(path))
    from kinema.config.waypoint_location import waypoint_store_for

    try:
        store = waypoint_store_for(config)
    except KinemaError:
        store = None
    if store is not None:
        files.append(Path(store.path))  # the copy saves go to (a bundled or inherited file's)
    return _unique(files)


def check_file_access(path: Path, config: Any, *, writing: bool = False) -> Path:
    """``path`` resolved (``..`` and symlinks followed) when the rules allow it.

    Args:
        path: the file.
        config: the running config (a ResolvedConfig, or None offline).
        writing: the file is to be written (a file directly in the system's temporary folder is allowed).

    Raises:
        FileAccessError: inside a security folder, outside every allowed folder, or (writing) a file
            the robot rule protects; the message names the rule (and the folders allowed).
    """
    import tempfile

    resolved = Path(path).expanduser().resolve()
    for folder in security_folders():
        if resolved.is_relative_to(folder.resolve()):
            raise FileAccessError(f"{path} is refused by the {SECURITY_RULE} ({folder})")
    if writing and any(resolved == file.resolve() for file in protected_from_writing(config)):
        raise FileAccessError(f"{path} is refused by the {ROBOT_RULE}")
    allowed = allowed_folders(config)
    if any(resolved.is_relative_to(folder.resolve()) for folder in allowed):
        return resolved
    if writing and resolved.parent == Path(tempfile.gettempdir()).resolve():
        return resolved
    where = f" (it resolves to {resolved})" if resolved != Path(path) else ""
    raise FileAccessError(
        f"{path}{where} is refused by the {FILE_RULE}: {', '.join(str(f) for f in allowed)}"
    )


def _unique(folders: Iterable[Path]) -> list[Path]:
    return list(dict.fromkeys(folders))
