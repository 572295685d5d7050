"""MuJoCo's OpenGL backend, chosen before mujoco is first imported: import this module first.

MuJoCo reads ``MUJOCO_GL`` once, when ``mujoco`` is imported, and keeps that backend for the process. A
module of Kinema that imports mujoco (the driver, the view's scene model, the planning scene, the frame
tree) imports this one before it, so whichever comes first in a process, a later camera renders through
EGL headless instead of failing with ``gladLoadGL error`` under the GLFW default.
"""

from __future__ import annotations

import os
import sys

# Set beside MUJOCO_GL when Kinema chose the backend, so a child process can tell it from the user's choice.
CHOSEN_BY_KINEMA = "KINEMA_MUJOCO_GL_CHOSEN"
# True when mujoco was already loaded (with its default backend) by the time Kinema chose one.
imported_too_early = False


def choose_gl_backend() -> None:
    """Pick MuJoCo's OpenGL backend before mujoco is first imported (it reads MUJOCO_GL then).

    MuJoCo defaults to GLFW, which needs a display. Without one, render headless through EGL — but only
    when its libraries load: ``import mujoco`` itself fails with MUJOCO_GL=egl and no libEGL. Without
    them rendering is disabled, so the simulation still runs and the cameras say what to install. A
    MUJOCO_GL the user set is left alone.
    """
    global imported_too_early
    if "MUJOCO_GL" in os.environ or sys.platform != "linux":
        return
    imported_too_early = "mujoco" in sys.modules
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return
    import ctypes

    def loads(*names: str) -> bool:
        for name in names:
            try:
                ctypes.CDLL(name)
            except OSError:
                continue
            return True
        return False

    usable = loads("libEGL.so.1", "libEGL.so") and loads("libOpenGL.so.0", "libGL.so.1", "libGL.so")
    os.environ["MUJOCO_GL"] = os.environ[CHOSEN_BY_KINEMA] = "egl" if usable else "disable"


def no_rendering() -> None:
    """For a process that reads MuJoCo models but never renders (the agent; the driver renders): no OpenGL
    backend, so ``import mujoco`` loads no PyOpenGL, EGL or Mesa (about 5 MB resident). Call it before
    mujoco is imported. A backend the user chose is left alone; one Kinema chose for a parent process
    (the supervisor's, inherited through the environment) is not the user's.
    """
    chosen = os.environ.get("MUJOCO_GL")
    if chosen is None or chosen == os.environ.get(CHOSEN_BY_KINEMA):
        os.environ["MUJOCO_GL"] = os.environ[CHOSEN_BY_KINEMA] = "disable"


choose_gl_backend()
