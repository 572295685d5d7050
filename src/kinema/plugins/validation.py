"""Checking a config's objectives against its behaviors, and exporting the behaviors for Groot2.

Every objective file of the config's merged objective library is validated with the engine's
validation (unknown behavior IDs with the closest names, ports a behavior does not declare, literals
that do not convert to the port's type, missing subtrees), using a factory populated from the config's
behavior registry, exactly as the objective server would build it.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from kinema.errors import SourceLocation

if TYPE_CHECKING:
    from kinema.bt.validation import Problem
    from kinema.config import ResolvedConfig
    from kinema.plugins.registry import BehaviorRegistry


def validate_objectives(
    resolved: ResolvedConfig, registry: BehaviorRegistry
) -> tuple[int, list[Problem], list[str]]:
    """Validate every objective file of ``resolved``; return (number of files, problems, warnings).

    Files that do not parse and duplicate definitions are problems too, with their ``file:line``. The
    warnings (``file:line: ...``) are the library's (an objective ID defined twice in one folder) and one
    per node written in a former spelling (``CreateStampedPose is MoveIt Pro's old name of ...``) and one
    per waypoint name an objective writes that the config has not saved.
    """
    from kinema.bt.validation import Problem, validate_files
    from kinema.config import ObjectiveLibrary

    library = ObjectiveLibrary.load(resolved)
    problems: list[Problem] = [
        Problem(error.location or SourceLocation("<objectives>"), error.message) for error in library.errors
    ]
    files = library.files()
    spelled: list[Problem] = []
    problems += validate_files(list(files), registry.create_factory(), warnings=spelled)
    from kinema.config.waypoint_uses import config_waypoint_warnings

    waypoints = config_waypoint_warnings(files, resolved)
    return len(files), problems, [*library.warnings, *(str(note) for note in spelled), *waypoints]


def write_tree_nodes_model(registry: BehaviorRegistry, path: Path) -> Path:
    """Write the ``<TreeNodesModel>`` of the registry's behaviors (for Groot2) to ``path``."""
    from kinema.bt import write_tree_nodes_model_xml
    from kinema.config.atomic_write import atomic_write_text

    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, write_tree_nodes_model_xml(registry.create_factory()))
    return path
