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
from typing import Any

import kinema.mujoco_gl  # noqa: F401  (picks MuJoCo's OpenGL backend before mujoco loads)

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
