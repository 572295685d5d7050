"""lab_sim's driver: MuJoCo stepped headless, served as ros2_control-like controllers.

* :class:`MujocoDriver` (``driver.py``) — the in-process driver: ``MujocoDriver(session, settings)``,
  ``start()``/``stop()`` or ``with``;
* :class:`MujocoDriverSettings` (``settings.py``) — scene, speed, rates, controllers;
  ``MujocoDriverSettings.from_config("lab_sim", sim_speed=math.inf)``;
* :func:`parse_sim_speed` — ``"1"``, ``"4"``, ``"max"`` → a factor;
* :mod:`kinema.drivers.mujoco.names` — the topic, service and action names it serves;
* ``python -m kinema.drivers.mujoco --help`` — the driver as a process;
* ``cameras.py`` — the scene's cameras rendered offscreen and served while someone subscribes.

Names are imported lazily, so importing this package (or ``names``) does not load mujoco.
"""

from __future__ import annotations

import importlib
import os
import sys
from typing import Any


def _choose_gl_backend() -> None:
    """Pick MuJoCo's OpenGL backend before mujoco is first imported (it reads MUJOCO_GL then).

    MuJoCo defaults to GLFW, which needs a display. Without one, render headless through EGL — but only
    when its libraries load: ``import mujoco`` itself fails with MUJOCO_GL=egl and no libEGL. Without
    them rendering is disabled, so the simulation still runs and the cameras say what to install. A
    MUJOCO_GL the user set is left alone.
    """
    if "MUJOCO_GL" in os.environ or sys.platform != "linux":
        return
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
    os.environ["MUJOCO_GL"] = "egl" if usable else "disable"


_choose_gl_backend()

_EXPORTS = {
    "MujocoDriver": "driver",
    "MujocoDriverSettings": "settings",
    "parse_sim_speed": "sim_speed",
    "format_sim_speed": "sim_speed",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'kinema.drivers.mujoco' has no attribute {name!r}")
    return getattr(importlib.import_module(f"kinema.drivers.mujoco.{module}"), name)
