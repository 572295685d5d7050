"""Where a config's waypoints are saved: never into a package the config inherits from or Kinema ships.

``objectives.waypoints_file`` may name a file of another package: a config based on lab_sim inherits
lab_sim's reference, and a bundled config's file lies inside Kinema's installation. Saving a waypoint
there would change the parent for every config based on it (and an installed package for every user),
so changes go elsewhere, and the first change copies the inherited waypoints over:

* the config's own file (the reference names a file of the config package, in the workspace): in place;
* a workspace config whose file belongs to another package: ``<config>/waypoints/<file name>``;
* a config bundled with Kinema: ``<user data>/kinema/waypoints/<config>/<file name>``
  (``$XDG_DATA_HOME`` or ``~/.local/share`` on Linux).

Until that copy exists, waypoints are read from the inherited file; afterwards from the copy.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from kinema.config.refs import as_ref
from kinema.config.waypoints import WaypointStore

if TYPE_CHECKING:
    from kinema.config.inheritance import ResolvedConfig

WAYPOINTS_KEY = "objectives.waypoints_file"


def user_waypoints_dir() -> Path:
    """The user data folder holding waypoints saved for bundled configs (not created here)."""
    import platformdirs

    return platformdirs.user_data_path("kinema") / "waypoints"


def waypoint_store_for(resolved: ResolvedConfig) -> WaypointStore | None:
    """The waypoint store of a resolved config (None when it names no waypoints file).

    The store's ``notice`` says where changes go when that is not the file the config names.

    Raises:
        ConfigError: the waypoints file reference does not resolve.
    """
    source = resolved.waypoints_path
    if source is None:
        return None
    config = resolved.package
    ref = as_ref(resolved.get(WAYPOINTS_KEY))
    owner = ref.package if ref is not None else config.name
    owner_name = resolved.workspace.package(owner).name if resolved.workspace.has_package(owner) else owner
    if config.origin != "bundled" and owner_name == config.name:
        return WaypointStore(source)
    if config.origin != "bundled":
        target = config.path / "waypoints" / source.name
        notice = (
            f"config {config.name!r} takes its waypoints from package {owner_name!r} ({source}); saved "
            f"waypoints go to {target} so that {owner_name!r} stays as it is (set {WAYPOINTS_KEY} to "
            f"{{package_name: {config.name}, relative_path: waypoints/{source.name}}} to make it explicit)"
        )
    else:
        target = user_waypoints_dir() / config.name / source.name
        notice = (
            f"config {config.name!r} is bundled with Kinema, so saved waypoints go to {target} (its own "
            f"file {source} stays as shipped); make a config of your own with "
            f"`kinema new config NAME --based-on {config.name}` to keep them in your workspace"
        )
    if target.resolve() == source.resolve():
        return WaypointStore(source)
    return WaypointStore(target, seed_from=source, notice=notice)
