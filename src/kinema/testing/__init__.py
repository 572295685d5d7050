"""Testing behaviors: run one behavior or one objective in a test, with or without pytest.

The pytest plugin (:mod:`kinema.testing.plugin`, loaded automatically once Kinema is installed) wraps
these functions in fixtures; ``kinema test`` runs a workspace's behavior package tests with it.
"""

from __future__ import annotations

from kinema.testing.harness import (
    BehaviorRun,
    InProcessRuntime,
    ObjectiveRunResult,
    build_tree,
    load_behavior_package,
    publish_repeatedly,
    registry_of,
    run_objective,
    runtime_in_process,
    tick_behavior,
    tick_until_done,
)

__all__ = [
    "BehaviorRun",
    "InProcessRuntime",
    "ObjectiveRunResult",
    "build_tree",
    "load_behavior_package",
    "publish_repeatedly",
    "registry_of",
    "run_objective",
    "runtime_in_process",
    "tick_behavior",
    "tick_until_done",
]
