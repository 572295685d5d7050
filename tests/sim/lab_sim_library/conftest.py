"""Fixtures: lab_sim with MoveIt Pro's own lab_sim objective library, running headless at max sim speed.

The workspace holds a package ``lab_sim`` that overlays the bundled one: the bundled config, description
and waypoints, with its objectives folder replaced by a copy of ``../shared/compat/moveit_pro/lab_sim/
objectives`` made at test time (never committed). Kinema's core objective library stays, as MoveIt
Pro's core library does beside lab_sim. Files the objectives save land in that temporary copy.
"""

from __future__ import annotations

import shutil
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from lab_sim_library_cell import LibraryCell

from kinema.resources import bundled_dir
from kinema.transport import free_endpoint

SHARED = Path(__file__).resolve().parents[3].parent / "shared"
CORPUS = SHARED / "compat" / "moveit_pro" / "lab_sim" / "objectives"


def _workspace(root: Path) -> Path:
    package = root / "src" / "lab_sim"
    shutil.copytree(bundled_dir("configs") / "lab_sim", package, ignore=shutil.ignore_patterns("objectives"))
    shutil.copytree(CORPUS, package / "objectives")
    return package / "objectives"


@pytest.fixture(scope="module")
def library_cell(
    tmp_path_factory: pytest.TempPathFactory, request: pytest.FixtureRequest
) -> Iterator[LibraryCell]:
    """Router, MuJoCo driver (max sim speed, or the test module's ``SIM_SPEED``), agent and SDK client on a
    free loopback port."""
    if not CORPUS.is_dir():
        pytest.skip(f"MoveIt Pro's lab_sim objectives are not at {CORPUS}")
    import math

    from kinema.config import Workspace
    from kinema.drivers.mujoco import MujocoDriver, MujocoDriverSettings
    from kinema.runtime.agent_process import AgentOptions, build_agent
    from kinema.sdk import ObjectiveClient
    from kinema.transport import Node, host_router, open_session

    root = tmp_path_factory.mktemp("ws")
    objectives = _workspace(root)
    cleanup: list[Callable[[], Any]] = []
    try:
        endpoint = free_endpoint()
        router = host_router(endpoint)
        cleanup.append(router.close)
        driver_session = open_session(endpoint)
        cleanup.append(driver_session.close)
        speed = getattr(request.module, "SIM_SPEED", math.inf)
        settings = MujocoDriverSettings.from_config("lab_sim", Workspace.discover(root), sim_speed=speed)
        driver = MujocoDriver(driver_session, settings)
        driver.start()
        cleanup.append(driver.stop)
        agent_session = open_session(endpoint)
        cleanup.append(agent_session.close)
        agent = build_agent(
            AgentOptions(config="lab_sim", workspace=root, clock="sim", hot_reload=False), agent_session
        )
        agent.start()
        cleanup.append(agent.close)
        client_session = open_session(endpoint)
        cleanup.append(client_session.close)
        client = ObjectiveClient(session=client_session)
        cleanup.append(client.close)
        client.wait_for_runtime()
        yield LibraryCell(client, Node(client_session, "lab_sim_library_probe"), objectives, driver, endpoint)
    finally:
        for step in reversed(cleanup):
            step()
