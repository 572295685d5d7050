"""Waypoint names that objectives write literally, checked against a config's waypoints before a run.

An objective copied from another config (MoveIt Pro's ``Move to Waypoint`` with ``waypoint_name="Arm
Forward"``) validates, then fails where it runs: "unknown waypoint". The ports called ``waypoint_name``
(``RetrieveWaypoint``'s, the ``Move to Waypoint`` subtrees') and the defaults objectives declare for them
are compared with the config's saved waypoints, and each name that is not there is a warning, not an
error: a waypoint may still be saved before the objective runs (``kinema waypoint save``).
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from pathlib import Path
from typing import TYPE_CHECKING

from kinema.errors import KinemaError, SourceLocation

if TYPE_CHECKING:
    from kinema.config.inheritance import ResolvedConfig

# The port every MoveIt Pro and Kinema behavior or subtree that goes to a saved waypoint names it with.
WAYPOINT_PORT = "waypoint_name"
_MODEL_PORTS = ("input_port", "inout_port")


def _literal(value: str | None) -> str | None:
    """A waypoint name written as such; None for a blackboard entry, a ``$(...)`` substitution or nothing."""
    text = (value or "").strip()
    if not text or text.startswith("{") or "$(" in text:
        return None
    return text


def waypoint_names_used(path: Path) -> list[tuple[SourceLocation, str]]:
    """Each literal waypoint name in objective file ``path`` with where it is written (an unreadable file
    gives none: the validator reports it)."""
    from kinema.bt.xmlsource import parse_xml_file

    try:
        root = parse_xml_file(path)
    except KinemaError:
        return []
    used: list[tuple[SourceLocation, str]] = []
    for tree in root.iter("BehaviorTree"):
        for element in tree.iter():
            if isinstance(element.tag, str) and (name := _literal(element.get(WAYPOINT_PORT))):
                used.append((SourceLocation(str(path), element.sourceline or 0), name))
    for model in root.iter("TreeNodesModel"):
        for port in model.iter(*_MODEL_PORTS):
            if port.get("name") == WAYPOINT_PORT and (name := _literal(port.get("default"))):
                used.append((SourceLocation(str(path), port.sourceline or 0), name))
    return used


def unknown_waypoint_warnings(paths: Iterable[Path], known: Collection[str], config: str) -> list[str]:
    """``file:line: ...`` for each literal waypoint name in ``paths`` that is not among ``known``."""
    import difflib

    warnings = []
    for path in paths:
        for location, name in waypoint_names_used(Path(path)):
            if name in known:
                continue
            # One line each, short: a folder copied from another config names many of its waypoints, and the
            # full list repeated on every line drowned them (`kinema waypoint list` prints it once).
            close = difflib.get_close_matches(name, sorted(known), n=3, cutoff=0.6)
            hint = (
                "did you mean " + " or ".join(repr(c) for c in close) + "?"
                if close
                else f"it has {len(known)}: `kinema waypoint list -c {config}`"
            )
            warnings.append(
                f"{location}: waypoint {name!r} is not one of config {config}'s waypoints ({hint}); the "
                f"objective fails there unless it is saved first (`kinema waypoint save {name!r}`)"
            )
    return warnings


def saved_waypoint_names(resolved: ResolvedConfig) -> list[str] | None:
    """The names of ``resolved``'s saved waypoints; None when the config has no waypoints file, or when it
    does not load (its own check says why)."""
    from kinema.config.waypoint_location import waypoint_store_for

    try:
        store = waypoint_store_for(resolved)
        return store.names() if store is not None else None
    except KinemaError:
        return None


def config_waypoint_warnings(
    paths: Iterable[Path], resolved: ResolvedConfig, config_name: str | None = None
) -> list[str]:
    """:func:`unknown_waypoint_warnings` against ``resolved``'s saved waypoints (none without them, see
    :func:`saved_waypoint_names`); ``config_name`` names the config in the warnings instead of ``resolved``
    (a scratch config standing for the user's)."""
    known = saved_waypoint_names(resolved)
    name = config_name or resolved.name
    return [] if known is None else unknown_waypoint_warnings(paths, known, name)
