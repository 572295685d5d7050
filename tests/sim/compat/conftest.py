"""Fixtures: a lab_sim cell (router, driver, agent, client) and a copy of MoveIt Pro's objectives."""

from __future__ import annotations

import math
import shutil
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from compat_cell import CONFIG, Cell, make_workspace

from kinema.transport import free_endpoint


@pytest.fixture(scope="module")
def start_cell(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[Callable[..., Cell]]:
    """Factory: ``start_cell(objectives=None, sim_speed=math.inf, driver=True)`` starts a cell.

    ``driver=False`` leaves the driver out (a test starts it, e.g. as a process it can kill).
    """
    from kinema.config import Workspace
    from kinema.drivers.mujoco import MujocoDriver, MujocoDriverSettings
    from kinema.runtime.agent_process import AgentOptions, build_agent
    from kinema.sdk import ObjectiveClient
    from kinema.transport import Node, host_router, open_session

    cleanup: list[Callable[[], Any]] = []
    cells: list[Cell] = []
    request.getfixturevalue("show_on_failure")(
        request.node, "the cells' arms", lambda: "\n".join(cell.describe() for cell in cells) or "(no cell)"
    )

    def start(
        objectives: Path | None = None,
        sim_speed: float = math.inf,
        driver: bool = True,
        extra_objectives: Path | None = None,
    ) -> Cell:
        root = make_workspace(tmp_path_factory.mktemp("ws"), objectives)
        endpoint = free_endpoint()
        router = host_router(endpoint)
        cleanup.append(router.close)
        sim = None
        if driver:
            driver_session = open_session(endpoint)
            cleanup.append(driver_session.close)
            settings = MujocoDriverSettings.from_config(CONFIG, Workspace.discover(root), sim_speed=sim_speed)
            sim = MujocoDriver(driver_session, settings)
            sim.start()
            cleanup.append(sim.stop)
        agent_session = open_session(endpoint)
        cleanup.append(agent_session.close)
        options = AgentOptions(
            config=CONFIG,
            workspace=root,
            objective_dirs=[extra_objectives] if extra_objectives else [],
            clock="sim",
            hot_reload=False,
        )
        agent = build_agent(options, agent_session)
        agent.start()
        cleanup.append(agent.close)
        client_session = open_session(endpoint)
        cleanup.append(client_session.close)
        client = ObjectiveClient(session=client_session)
        cleanup.append(client.close)
        client.wait_for_runtime()
        node = Node(client_session, "compat_probe")
        cells.append(Cell(sim, agent, client, node, root, endpoint))
        return cells[-1]

    yield start
    for step in reversed(cleanup):
        step()


@pytest.fixture(scope="module")
def compat_objectives(shared_dir_module: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh copy of the MoveIt Pro objective files (never the originals, never committed)."""
    source = shared_dir_module / "compat" / "moveit_pro" / "objectives"
    if not source.is_dir():
        pytest.skip(f"MoveIt Pro compatibility fixtures not found at {source}")
    copy = tmp_path_factory.mktemp("moveit_pro") / "objectives"
    shutil.copytree(source, copy)
    return copy


@pytest.fixture(scope="module")
def shared_dir_module() -> Path:
    """``../shared`` next to the checkout (module scope); skips when it is absent."""
    shared = Path(__file__).resolve().parents[3].parent / "shared"
    if not shared.is_dir():
        pytest.skip("../shared (the MoveIt Pro compatibility fixtures) is not available in this checkout")
    return shared
