"""`kinema view` left running across `kinema down` and `kinema run -c OTHER` draws OTHER's scene.

A new user's view kept saying (and drawing) lab_sim after the tutorial switched the runtime to
example_config: the scene was resolved once, at start. Now the view follows the config the runtime's agent
announces, unless ``-c`` chose what to draw, and says on the page why when it cannot.
"""

from __future__ import annotations

import socket
import time
from collections.abc import Callable

import pytest


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def _until(condition: Callable[[], bool], timeout: float = 20.0) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.05)
    return condition()


def test_the_view_draws_the_config_the_runtime_runs_or_says_why_not(monkeypatch: pytest.MonkeyPatch) -> None:
    from kinema.transport import free_endpoint, host_router, open_session
    from kinema.transport.presence import AGENT, declare_presence
    from kinema.viz.view import ViewerOptions, start_viewer

    monkeypatch.setenv("KINEMA_CONFIG", "lab_sim")  # what the view draws first: the active config
    endpoint = free_endpoint()
    with host_router(endpoint), open_session(endpoint) as agent_side:
        notes: list[str] = []
        viewer = start_viewer(
            ViewerOptions(endpoint=endpoint, port=_free_port(), open_browser=False, echo=notes.append)
        )
        try:
            assert viewer.source.config == "lab_sim"
            first = declare_presence(agent_side, AGENT, config="example_config")
            said = "3D view now draws config example_config (what the runtime runs)"
            assert _until(lambda: said in notes), notes  # said once the new scene is drawn
            assert viewer.source.config == "example_config"
            assert viewer.bridge is not None and "config example_config" in viewer.bridge.status()["info"]
            first.close()
            declare_presence(agent_side, AGENT, config="config_of_another_machine")
            assert _until(lambda: "cannot draw" in (viewer.bridge.status()["banner"] or "")), notes
            banner = viewer.bridge.status()["banner"]
            assert "The runtime runs config config_of_another_machine" in banner
            assert "it draws example_config" in banner
            assert viewer.source.config == "example_config"
        finally:
            viewer.close()


def test_the_page_keeps_how_the_last_run_ended_once_the_server_is_idle() -> None:
    # The info line read "objective 3 Waypoints Pick and Place: Idle" after a cancel (and after a success).
    from types import SimpleNamespace

    from kinema.resources import bundled_dir
    from kinema.transport import open_session
    from kinema.viz.scene_model import SceneModel
    from kinema.viz.scene_viewer import SceneViewer

    model = SceneModel.from_file(bundled_dir("configs") / "lab_sim" / "description" / "lab_sim_scene.xml")
    with open_session([]) as session:
        viewer = SceneViewer(session, model, SimpleNamespace(), config="lab_sim")  # type: ignore[arg-type]

        def beat(name: str, status: str) -> str:
            viewer._on_heartbeat(SimpleNamespace(objective_name=name, objective_status=status))
            return str(viewer.status()["info"])

        assert "objective Pick: Running" in beat("Pick", "Running")
        beat("Pick", "Cancelled")
        assert "objective Pick: Cancelled · idle" in beat("Pick", "Idle")
        assert "objective Pick: Cancelled · idle" in beat("Pick", "Idle")  # every later beat too
        assert "objective Place: Idle" in beat("Place", "Idle")
