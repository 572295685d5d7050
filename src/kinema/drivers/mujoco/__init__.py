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

from typing import Any

import kinema.mujoco_gl  # noqa: F401  (picks MuJoCo's OpenGL backend before mujoco loads)
from kinema.lazy_exports import LazyExports

_EXPORTS = {
    "MujocoDriver": "driver",
    "MujocoDriverSettings": "settings",
    "parse_sim_speed": "sim_speed",
    "format_sim_speed": "sim_speed",
}
_lazy = LazyExports(__name__, _EXPORTS)

__all__ = _lazy.names


def __getattr__(name: str) -> Any:
    return _lazy.attribute(name)
