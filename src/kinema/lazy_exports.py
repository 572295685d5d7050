"""Packages whose public names are imported on first use, so importing the package stays cheap.

``kinema.motion`` must not load pinocchio, ``kinema.sdk`` the engine, ``kinema.drivers.mujoco`` mujoco, until
a name that needs it is used. Each such package lists its names and the module defining each, and hands
the lookup to one :class:`LazyExports`::

    _EXPORTS = {"RobotModel": "robot_model", "Agent": "kinema.runtime.agent"}
    _lazy = LazyExports(__name__, _EXPORTS)
    __all__ = _lazy.names


    def __getattr__(name: str) -> Any:
        return _lazy.attribute(name)

A module is named relative to the package (``robot_model``) or in full (``kinema.runtime.agent``). A name
is imported once and then kept in the package's namespace, so the next lookup does not come here.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Mapping
from typing import Any

__all__ = ["LazyExports"]


class LazyExports:
    """The lazily imported names of package ``package``: name -> the module that defines it."""

    def __init__(self, package: str, exports: Mapping[str, str]) -> None:
        self.package = package
        self.exports = dict(exports)

    @property
    def names(self) -> list[str]:
        """The exported names, sorted (the package's ``__all__``)."""
        return sorted(self.exports)

    def attribute(self, name: str) -> Any:
        """Import and return ``name`` (the package's ``__getattr__``).

        Raises:
            AttributeError: ``name`` is not one of the package's names.
        """
        module = self.exports.get(name)
        if module is None:
            raise AttributeError(f"module {self.package!r} has no attribute {name!r}")
        full = module if module.startswith("kinema.") else f"{self.package}.{module}"
        value = getattr(importlib.import_module(full), name)
        setattr(sys.modules[self.package], name, value)
        return value
