"""Kinema: an open-source, pure-Python robot application runtime.

Objectives are BehaviorTree.CPP v4 XML, Behaviors are Python plugins, the robot runs in MuJoCo or on
hardware, and everything talks over zenoh with the rmw_zenoh wire format.
"""

from __future__ import annotations

import sys

if sys.dont_write_bytecode:  # keep compiled code in the user's cache instead of compiling at every start
    from kinema.bytecode import cache_own_modules

    cache_own_modules()

__version__ = "0.1.0"

__all__ = ["__version__"]
