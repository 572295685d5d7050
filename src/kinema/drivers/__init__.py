"""Drivers: processes that own hardware or a simulator and serve it as topics, services and actions.

* :class:`Driver` is the contract (``start``, ``stop``, ``interfaces``) and :class:`ServedInterface`
  one thing a driver offers;
* :data:`DRIVERS`, :func:`driver_spec` and :func:`drivers_for_config` say which drivers exist, which a
  config package needs, and how to run each as a process (:meth:`DriverSpec.command`) or in-process
  (:meth:`DriverSpec.load`);
* :mod:`kinema.drivers.mujoco` is lab_sim's simulator (``python -m kinema.drivers.mujoco --help``).

Importing this package imports neither mujoco nor zenoh.
"""

from __future__ import annotations

from kinema.drivers.protocol import Driver, InterfaceKind, ServedInterface
from kinema.drivers.registry import DRIVERS, DriverSpec, driver_spec, drivers_for_config

__all__ = [
    "DRIVERS",
    "Driver",
    "DriverSpec",
    "InterfaceKind",
    "ServedInterface",
    "driver_spec",
    "drivers_for_config",
]
