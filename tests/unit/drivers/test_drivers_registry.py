"""Which drivers a config needs and how each is launched."""

from __future__ import annotations

import sys
from typing import Any

import pytest

from kinema.config import resolve_config
from kinema.drivers import DRIVERS, driver_spec, drivers_for_config
from kinema.errors import DriverError


class NoSimulation:
    """A resolved config without a MuJoCo scene (only ``get`` and ``urdf_params`` are consulted)."""

    def __init__(self, urdf_params: dict[str, str] | None = None, simulated: bool | None = None) -> None:
        self.urdf_params = urdf_params or {}
        self.simulated = simulated

    def get(self, key: str, default: Any = None) -> Any:
        return self.simulated if key == "hardware.simulated" else default


def test_lab_sim_needs_the_mujoco_driver() -> None:
    assert [spec.name for spec in drivers_for_config(resolve_config("lab_sim"))] == ["mujoco"]


def test_a_config_without_a_scene_needs_no_driver() -> None:
    assert drivers_for_config(NoSimulation()) == []  # type: ignore[arg-type]


def test_moveit_pro_s_urdf_params_scene_needs_the_mujoco_driver_unless_the_config_is_for_hardware() -> None:
    # A MoveIt Pro package names its scene as a xacro argument; it ran with no simulation at all.
    scene = {"mujoco_model": "description/scene.xml"}
    assert [spec.name for spec in drivers_for_config(NoSimulation(scene))] == ["mujoco"]  # type: ignore[arg-type]
    assert drivers_for_config(NoSimulation(scene, simulated=False)) == []  # type: ignore[arg-type]


def test_the_command_line_runs_the_module_with_the_options_given() -> None:
    argv = driver_spec("mujoco").command(
        config="lab_sim",
        connect="tcp/127.0.0.1:7448",
        sim_speed="max",
        log_file="/tmp/x/mujoco.log",
        ready_fd=5,
    )
    assert argv[:3] == [sys.executable, "-m", "kinema.drivers.mujoco"]
    assert argv[3:] == [
        "--config",
        "lab_sim",
        "--connect",
        "tcp/127.0.0.1:7448",
        "--sim-speed",
        "max",
        "--log-file",
        "/tmp/x/mujoco.log",
        "--ready-fd",
        "5",
    ]


def test_the_in_process_class_implements_the_driver_protocol() -> None:
    cls = driver_spec("mujoco").load()
    assert cls.name == "mujoco"
    for method in ("start", "stop", "interfaces"):
        assert callable(getattr(cls, method))


def test_an_unknown_driver_lists_the_known_ones() -> None:
    with pytest.raises(DriverError, match=r"mujoc.*mujoco"):
        driver_spec("mujoc")
    assert set(DRIVERS) == {"mujoco"}
