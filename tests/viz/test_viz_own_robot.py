"""kinema view draws a robot made from its URDF with its visual meshes: the Panda of example-robot-data.

Needs Debian's ``chromium`` and example-robot-data; skipped with a hint when either is missing.
"""

from __future__ import annotations

import io
import os
import socket
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from headless_chromium import HeadlessChromium, find_chromium

from kinema.config.robot_files import PackageIndex

pytestmark = pytest.mark.slow

CHROMIUM = find_chromium()
if CHROMIUM is None:
    pytest.skip("chromium is not installed (apt-get install -y chromium)", allow_module_level=True)
if PackageIndex().find("example-robot-data") is None:
    pytest.skip(
        "example-robot-data is not installed (pip install example-robot-data)", allow_module_level=True
    )

PANDA = "package://example-robot-data/robots/panda_description"


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def _pixels(png: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int16)


@pytest.fixture(scope="module")
def panda_view(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Any, HeadlessChromium]]:
    from kinema.config import Workspace
    from kinema.drivers.mujoco import MujocoDriver, MujocoDriverSettings
    from kinema.scaffold.robot_package import new_robot_package
    from kinema.transport import free_endpoint, host_router
    from kinema.viz.view import ViewerOptions, start_viewer

    root = tmp_path_factory.mktemp("view_ws")
    (root / "src").mkdir()
    workspace = Workspace.discover(root)
    new_robot_package(
        "panda_view", f"{PANDA}/urdf/panda.urdf", srdf=f"{PANDA}/srdf/panda.srdf", workspace=workspace
    )
    endpoint = free_endpoint()
    router = host_router(endpoint)
    driver = MujocoDriver(router, MujocoDriverSettings.from_config("panda_view", Workspace.discover(root)))
    driver.start()
    viewer = start_viewer(
        ViewerOptions(
            endpoint=endpoint, config="panda_view", workspace=root, port=_free_port(), open_browser=False
        )
    )
    try:
        assert CHROMIUM is not None
        with HeadlessChromium(CHROMIUM, width=900, height=700) as browser:
            browser.navigate(viewer.url)
            browser.wait_for(
                "typeof viewer !== 'undefined' && kinema.framed && viewer.num_messages_received > 30",
                timeout=60,
            )
            browser.evaluate("document.getElementById('kinema-info').style.visibility = 'hidden'")
            yield viewer, browser
    finally:
        viewer.close()
        driver.stop()
        router.close()


def _shot(page: HeadlessChromium) -> bytes:
    page.evaluate(
        "window.__kinema_drawn=false;viewer.set_dirty();"
        "requestAnimationFrame(()=>requestAnimationFrame(()=>{window.__kinema_drawn=true;}))"
    )
    page.wait_for("window.__kinema_drawn", timeout=30.0)
    return page.screenshot()


def test_the_panda_is_drawn_with_its_visual_meshes(panda_view: tuple[Any, HeadlessChromium]) -> None:
    from kinema.viz import scene_commands as sc

    viewer, page = panda_view
    scene = viewer.bridge.scene
    meshes = [v for v in scene.visuals if v.kind == "mesh"]
    assert len(meshes) >= 10, "the Panda's converted DAE meshes are not among the drawn geoms"
    robot = [node for node in scene.bodies if not node.static and node.name.startswith("panda_")]
    with_robot = _shot(page)
    viewer.server.send([sc.set_property(node.path, "visible", False) for node in robot])
    try:
        without_robot = _shot(page)
    finally:
        viewer.server.send([sc.set_property(node.path, "visible", True) for node in robot])
    folder = os.environ.get("KINEMA_VIZ_SHOTS")
    if folder:
        Path(folder).mkdir(parents=True, exist_ok=True)
        (Path(folder) / "panda_view.png").write_bytes(with_robot)
    changed = np.abs(_pixels(with_robot) - _pixels(without_robot)).max(axis=2) > 30
    assert changed.sum() > 2000, "hiding the Panda changed too few pixels: it is not drawn"
