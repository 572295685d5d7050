"""Config packages: workspaces, config.yaml, inheritance with provenance, objective libraries, waypoints.

The public API other parts of Kinema use:

* :class:`Workspace` (``Workspace.discover(path | None)``, ``.packages``, ``.package(name)``) and
  :func:`list_config_packages`;
* :func:`active_selection` (``-w``/``-c`` flags > ``KINEMA_WORKSPACE``/``KINEMA_CONFIG`` > what
  ``kinema configure`` stored) and :func:`store_selection`;
* :func:`resolve_config` -> :class:`ResolvedConfig` (``.chain``, ``.data``, ``.provenance``,
  ``.package_dir(name)``, ``.resolve_file(ref)``, ``.urdf_path``, ``.waypoints_path``, ...);
* :class:`ObjectiveLibrary` (``ObjectiveLibrary.load(resolved)``, ``.objectives``, ``.get(id)``,
  ``.errors``, ``.save(id, xml_text)``) and :class:`ObjectiveInfo`;
* :class:`WaypointStore` (``names()``, ``get(name)``, ``save(waypoint)``, ``rename(old, new)``,
  ``erase(name)``) and :class:`Waypoint`.
"""

from __future__ import annotations

from kinema.config.inheritance import LibraryPath, ResolvedConfig, resolve_config
from kinema.config.objective_library import ObjectiveInfo, ObjectiveLibrary, ObjectivePort
from kinema.config.selection import Selection, active_selection, store_selection
from kinema.config.waypoints import Waypoint, WaypointStore
from kinema.config.workspace import Package, Workspace, list_config_packages

__all__ = [
    "LibraryPath",
    "ObjectiveInfo",
    "ObjectiveLibrary",
    "ObjectivePort",
    "Package",
    "ResolvedConfig",
    "Selection",
    "Waypoint",
    "WaypointStore",
    "Workspace",
    "active_selection",
    "list_config_packages",
    "resolve_config",
    "store_selection",
]
