"""A config package's robot as the planner loads it: the URDF file (xacro expanded) and where meshes are.

MoveIt Pro's packages describe the robot with xacro and ``urdf_params``; Kinema's generated ones with a
URDF whose meshes are ``package://`` URIs of an installed description package. Both reach pinocchio
through here: :func:`planning_urdf` expands a xacro once (with the config's ``urdf_params`` as
arguments, cached by content in the user's cache folder) and checks every mesh, so a missing mesh or a
Git LFS pointer is a ConfigError naming the file, never a pinocchio or MuJoCo parse error;
:func:`package_index` finds the packages the URIs name.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import TYPE_CHECKING

from kinema.config.robot_files import PackageIndex, resolve_robot

if TYPE_CHECKING:
    from kinema.config.inheritance import ResolvedConfig


def package_index(resolved: ResolvedConfig) -> PackageIndex:
    """The packages a config's robot files may name: the workspace's and bundled ones first, then
    ROS_PACKAGE_PATH, AMENT_PREFIX_PATH and pip-installed description packages."""
    return PackageIndex(packages={p.name: p.path for p in resolved.workspace.packages.values()})


def _cache_dir() -> Path:
    from platformdirs import user_cache_dir

    return Path(user_cache_dir("kinema")) / "urdf"


def planning_urdf(resolved: ResolvedConfig, *, check_meshes: bool = True) -> Path:
    """The URDF file to load the config's robot from.

    A ``.xacro`` description is expanded with the config's ``urdf_params`` and written to the cache (once
    per distinct text); a plain URDF is used where it is.

    Raises:
        ConfigError: the description cannot be read or expanded, a package is unknown, a mesh is
            missing or a Git LFS pointer (each naming the file and the line where known).
    """
    source = resolved.urdf_path
    is_xacro = source.name.endswith(".xacro")
    if not is_xacro and not check_meshes:
        return source
    robot = resolve_robot(source, xacro_args=resolved.urdf_params, index=package_index(resolved))
    if not is_xacro:
        return source
    text = robot.urdf_with_paths()
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()[:24]
    target = _cache_dir() / f"{source.name.removesuffix('.xacro')}-{digest}.urdf"
    if not target.is_file():
        from kinema.config.atomic_write import atomic_write_text

        target.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(target, '<?xml version="1.0"?>\n' + text)
    return target
