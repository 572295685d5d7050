"""Which drivers exist, which ones a config package needs, and how to launch each as a process.

``kinema run`` asks :func:`drivers_for_config` what to start for the selected config and runs each
:meth:`DriverSpec.command` as a child process (``-o`` starts only these, ``-n`` only the agent). Tests
and embedding programs build the driver in-process instead (:meth:`DriverSpec.load` gives the class).
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinema.errors import DriverError, did_you_mean

if TYPE_CHECKING:
    from kinema.config import ResolvedConfig


@dataclass(frozen=True)
class DriverSpec:
    """A kind of driver.

    Attributes:
        name: short name (``mujoco``); also the name of its log file in a run folder.
        module: the module whose ``main()`` runs the driver (``python -m <module>``).
        class_path: ``module:Class`` of the in-process driver (it implements :class:`Driver`).
        description: one line for people.
        wanted_by: predicate on a resolved config: does this config need the driver?
    """

    name: str
    module: str
    class_path: str
    description: str
    wanted_by: Callable[[ResolvedConfig], bool]

    def command(
        self,
        *,
        config: str,
        connect: str | None = None,
        workspace: str | Path | None = None,
        sim_speed: str | float | None = None,
        log_file: str | Path | None = None,
        ready_fd: int | None = None,
        verbose: bool = False,
    ) -> list[str]:
        """The command line that runs this driver as a process of its own.

        Args:
            config: the config package to drive.
            connect: the router endpoint to join (default: the driver's own default).
            workspace: the workspace to resolve ``config`` in.
            sim_speed: for simulators, ``1`` (real time), a factor such as ``4``, or ``max``.
            log_file: write the log there in the run format (else to stderr).
            ready_fd: a file descriptor (inherited by the child) it writes ``ready`` to once serving.
            verbose: log at DEBUG level.
        """
        argv = [sys.executable, "-m", self.module, "--config", config]
        if connect:
            argv += ["--connect", connect]
        if workspace is not None:
            argv += ["--workspace", str(workspace)]
        if sim_speed is not None:
            argv += ["--sim-speed", str(sim_speed)]
        if log_file is not None:
            argv += ["--log-file", str(log_file)]
        if ready_fd is not None:
            argv += ["--ready-fd", str(ready_fd)]
        if verbose:
            argv.append("--verbose")
        return argv

    def load(self) -> type[Any]:
        """Import and return the in-process driver class."""
        module_name, _, attribute = self.class_path.partition(":")
        try:
            return getattr(importlib.import_module(module_name), attribute)  # type: ignore[no-any-return]
        except (ImportError, AttributeError) as error:
            raise DriverError(f"driver {self.name!r}: cannot load {self.class_path}: {error}") from error


def _has_mujoco_model(config: ResolvedConfig) -> bool:
    """A MuJoCo scene is named: Kinema's ``hardware.simulation.mujoco_model``, or MoveIt Pro's xacro argument
    ``urdf_params: - mujoco_model: PATH`` of a config that is not for real hardware (``simulated: false``).
    Whether the file is there is the driver's to say, with its path."""
    if config.get("hardware.simulation.mujoco_model") is not None:
        return True
    return "mujoco_model" in config.urdf_params and config.get("hardware.simulated") is not False


DRIVERS: dict[str, DriverSpec] = {
    "mujoco": DriverSpec(
        name="mujoco",
        module="kinema.drivers.mujoco",
        class_path="kinema.drivers.mujoco.driver:MujocoDriver",
        description="MuJoCo simulation with ros2_control-like controllers",
        wanted_by=_has_mujoco_model,
    ),
}


def driver_spec(name: str) -> DriverSpec:
    """The driver called ``name``.

    Raises:
        DriverError: no such driver (the message lists the known ones).
    """
    spec = DRIVERS.get(name)
    if spec is None:
        raise DriverError(f"no driver named {name!r}; {did_you_mean(name, DRIVERS)}")
    return spec


def drivers_for_config(config: ResolvedConfig) -> list[DriverSpec]:
    """The drivers ``config`` needs, e.g. ``mujoco`` when it names a MuJoCo scene (see _has_mujoco_model)."""
    return [spec for spec in DRIVERS.values() if spec.wanted_by(config)]
