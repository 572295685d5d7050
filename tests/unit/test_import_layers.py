"""The arrows between packages point one way, and each transport name has one home.

- ``kinema.runtime`` does not import ``kinema.viz`` (the view is a client of the agent, never a part of it);
- ``kinema.drivers`` imports nothing of ``kinema.runtime`` (drivers talk to the agent only over the
  transport; what both need, lifeline, log files and presence, is below both);
- no plugin imports ``kinema.runtime`` (behaviors get their cell from their context);
- a topic, service or action name is assigned at module level in one module only.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SRC = REPO / "src" / "kinema"


def _imports(path: Path) -> list[tuple[int, str]]:
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.append((node.lineno, node.module))
            # `from kinema import runtime` names the package as an attribute
            found += [(node.lineno, f"{node.module}.{alias.name}") for alias in node.names]
    return found


def _offenders(folder: Path, forbidden: str) -> list[str]:
    return [
        f"{path.relative_to(REPO)}:{line} imports {name}"
        for path in sorted(folder.rglob("*.py"))
        for line, name in _imports(path)
        if name == forbidden or name.startswith(forbidden + ".")
    ]


@pytest.mark.parametrize(
    ("folder", "forbidden"),
    [
        (SRC / "runtime", "kinema.viz"),
        (SRC / "drivers", "kinema.runtime"),
        (REPO / "plugins", "kinema.runtime"),
    ],
)
def test_imports_point_one_way(folder: Path, forbidden: str) -> None:
    assert _offenders(folder, forbidden) == []


# Names the agent serves that a core behavior calls over the transport, as MoveIt Pro's do; a plugin does
# not import kinema.runtime, so the behavior names it too (test_the_agent_names_a_behavior_calls_match).
CALLED_BY_NAME = {"/get_saved_waypoints"}


def test_each_transport_name_is_assigned_in_one_module() -> None:
    homes: dict[str, set[str]] = defaultdict(set)
    for root in (SRC, REPO / "plugins"):
        for path in root.rglob("*.py"):
            for node in ast.parse(path.read_text(encoding="utf-8")).body:
                if (
                    isinstance(node, ast.Assign)
                    and isinstance(node.value, ast.Constant)
                    and isinstance(node.value.value, str)
                    and node.value.value.startswith("/")
                    and len(node.value.value) > 1
                ):
                    homes[node.value.value].add(str(path.relative_to(REPO)))
    twice = {name: sorted(paths) for name, paths in homes.items() if len(paths) > 1}
    assert set(twice) <= CALLED_BY_NAME, twice


def test_the_waypoint_service_a_behavior_calls_is_the_one_the_agent_serves() -> None:
    from kinema import waypoint_services as waypoints
    from kinema.runtime import names

    assert names.GET_WAYPOINTS is waypoints.GET_WAYPOINTS_SERVICE
    path = REPO / "plugins" / "core" / "kinema_core_behaviors" / "waypoints" / "retrieve_waypoint.py"
    assert "GET_WAYPOINTS_SERVICE" in path.read_text(encoding="utf-8")
