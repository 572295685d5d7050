"""MuJoCo keeps the OpenGL backend it found at import: Kinema chooses one first, whoever imports mujoco."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

RENDER = """
import mujoco
model = mujoco.MjModel.from_xml_string('<mujoco><worldbody><geom size=".1"/></worldbody></mujoco>')
mujoco.Renderer(model, 32, 32).render()
print("rendered")
"""


def _run(code: str) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "DISPLAY", "WAYLAND_DISPLAY")}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=env)


def _egl_or_skip() -> None:
    probe = _run("import kinema.mujoco_gl, os; print(os.environ['MUJOCO_GL'])")
    assert probe.returncode == 0, probe.stderr
    if probe.stdout.strip() != "egl":
        pytest.skip("no EGL here: sudo apt-get install -y libegl1 libgl1 libgl1-mesa-dri")


@pytest.mark.parametrize(
    "first", ["kinema.viz.scene_model", "kinema.motion.planning_scene", "kinema.drivers.mujoco"]
)
def test_a_kinema_module_that_uses_mujoco_lets_it_render_headless(first: str) -> None:
    _egl_or_skip()
    run = _run(f"import {first}\n{RENDER}")
    assert run.returncode == 0 and "rendered" in run.stdout, run.stderr[-2000:]


def test_cameras_say_why_when_mujoco_was_imported_before_kinema() -> None:
    _egl_or_skip()
    code = """
from types import SimpleNamespace as NS
import mujoco
from kinema.drivers.mujoco.cameras import CameraServer
xml = '<mujoco><worldbody><camera name="c" pos="0 0 1"/><geom size=".1"/></worldbody></mujoco>'
session = NS(registry=NS(typestore=NS(types={})))
cameras = CameraServer(session, mujoco.MjModel.from_xml_string(xml), lambda: None, 1.0)
cameras._run()
print(cameras.unavailable)
"""
    run = _run(code)
    assert run.returncode == 0, run.stderr[-2000:]
    assert "mujoco was imported before Kinema chose its OpenGL backend" in run.stdout, run.stdout


NO_RENDERING = """
import os, sys
from kinema.mujoco_gl import no_rendering
no_rendering()
import mujoco
print(os.environ.get("MUJOCO_GL"), any(name.startswith("OpenGL") for name in sys.modules))
"""


def test_the_agent_loads_no_opengl_even_when_its_parent_chose_egl() -> None:
    _egl_or_skip()
    # `kinema run` chose EGL for itself (the driver renders); the agent inherits it, and never renders
    child = f"subprocess.run([sys.executable, '-c', {NO_RENDERING!r}])"
    inherited = _run(f"import kinema.mujoco_gl\nimport subprocess, sys\n{child}")
    assert inherited.returncode == 0, inherited.stderr[-2000:]
    assert inherited.stdout.split() == ["disable", "False"]


@pytest.mark.parametrize("chosen", ["egl", "osmesa"])
def test_a_backend_the_user_chose_is_kept_by_a_process_that_never_renders(chosen: str) -> None:
    env = {
        k: v
        for k, v in os.environ.items()
        if not k.endswith("MUJOCO_GL") and not k.startswith("KINEMA_MUJOCO")
    }
    code = (
        "import os\nfrom kinema.mujoco_gl import no_rendering\nno_rendering()\nprint(os.environ['MUJOCO_GL'])"
    )
    run = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=60,
        env={**env, "MUJOCO_GL": chosen},
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.strip() == chosen
