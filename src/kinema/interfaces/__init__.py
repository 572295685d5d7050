"""The ROS IDL interfaces Kinema serves and uses, and the registry that loads them.

The ``.msg``/``.srv``/``.action`` files live next to this module as ``<pkg>/{msg,srv,action}/``
(MoveIt Pro's public SDK names: ``moveit_studio_sdk_msgs``, ``moveit_studio_agent_msgs``, ...), so they
ship inside the wheel. ``load_interfaces()`` registers them, on top of the standard types rosbags
already knows (std_msgs, sensor_msgs, geometry_msgs, trajectory_msgs, action_msgs, ...), once per process.

The registry's names are imported on first use: a submodule such as ``kinema.interfaces.definition`` (the
type variables behaviors are written with) does not load rosbags and numpy.
"""

from __future__ import annotations

import functools
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinema.lazy_exports import LazyExports

if TYPE_CHECKING:
    from kinema.interfaces.registry import (
        ActionType,
        ServiceType,
        TypeRegistry,
        dds_type_name,
        split_type_name,
    )

_lazy = LazyExports(
    __name__,
    {
        name: "registry"
        for name in ("ActionType", "ServiceType", "TypeRegistry", "dds_type_name", "split_type_name")
    },
)

__all__ = [
    "ActionType",
    "ServiceType",
    "TypeRegistry",
    "dds_type_name",
    "interfaces_dir",
    "load_interfaces",
    "split_type_name",
]


def interfaces_dir() -> Path:
    """The folder holding the bundled ``<pkg>/{msg,srv,action}`` files."""
    return Path(str(resources.files("kinema.interfaces")))


@functools.cache
def load_interfaces() -> TypeRegistry:
    """Return the process-wide registry with every bundled interface registered (built on first call)."""
    from kinema.interfaces.registry import TypeRegistry

    registry = TypeRegistry()
    registry.add_directory(interfaces_dir())
    return registry


def __getattr__(name: str) -> Any:
    return _lazy.attribute(name)
