"""What the MuJoCo driver runs: the scene, the start keyframe, speed, rates, controllers, tolerances.

:meth:`MujocoDriverSettings.from_config` reads them from a config package: the scene and keyframe
from ``hardware.simulation.{mujoco_model, mujoco_keyframe}`` (or MoveIt Pro's ``urdf_params``), which
controllers run from ``ros2_control.controllers_active_at_startup`` / ``controllers_inactive_at_startup``,
and what each controller is, the gripper and the F/T sensor from :class:`kinema.config.cell.CellSettings`.
Nothing here names a robot: a scene built by hand gets only the joint state broadcaster and a trajectory
controller over every actuated joint.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinema.config.cell import ControllerSpec
from kinema.drivers.mujoco.gripper_controller import GripperSettings
from kinema.drivers.mujoco.names import JOINT_STATE_BROADCASTER, JOINT_TRAJECTORY_CONTROLLER
from kinema.drivers.mujoco.trajectory_goal import ToleranceDefaults
from kinema.errors import ConfigError

if TYPE_CHECKING:
    from kinema.config import ResolvedConfig, Workspace

DEFAULT_CONTROLLERS = (JOINT_STATE_BROADCASTER, JOINT_TRAJECTORY_CONTROLLER)


@dataclass(frozen=True)
class MujocoDriverSettings:
    """Everything the driver needs to run a scene.

    Attributes:
        model_path: the MJCF scene.
        keyframe: keyframe to start from (None: the model's default state).
        sim_speed: sim seconds per wall second; ``math.inf`` for as fast as possible.
        publish_rate: rate of ``/clock``, ``/joint_states`` and action feedback, Hz of sim time.
        scene_state_rate: rate of the scene-state topic for viewers, Hz of wall time.

        cameras: serve the scene's cameras (rendered only while someone subscribes).
        camera_rate: most frames per camera per wall second while subscribed (MoveIt Pro's lab_sim
            renders at 10 Hz).
        active_controllers: controllers active at start.
        inactive_controllers: controllers loaded but inactive at start.
        controllers: what each controller is (its ros2_control type and joints), by name; a name not
            here must be one of ros2_control's conventional names (``joint_trajectory_controller`` ...).
        gripper_joint: the joint the gripper controller commands (None: no gripper controller).
        force_torque_sensor: the site carrying the wrist's MuJoCo force and torque sensors
            (``<site>_force``, ``<site>_torque``), as ros2_control names the sensor; without it (None, or
            absent from the scene) there is no force/torque broadcaster, velocity-force controller or
            admittance controller.
        control_site: the site of the end effector's control frame (the velocity-force controller's;
            "" for none).
        tolerances: the trajectory controller's default tolerances.
        gripper: the gripper controller's thresholds.
        config: the config package the settings came from ("" when built by hand).
    """

    model_path: Path
    keyframe: str | None = None
    sim_speed: float = 1.0
    publish_rate: float = 100.0
    scene_state_rate: float = 30.0
    cameras: bool = True
    camera_rate: float = 10.0
    active_controllers: tuple[str, ...] = DEFAULT_CONTROLLERS
    inactive_controllers: tuple[str, ...] = ()
    controllers: Mapping[str, ControllerSpec] = field(default_factory=dict)
    gripper_joint: str | None = None
    force_torque_sensor: str | None = None
    control_site: str = ""
    tolerances: ToleranceDefaults = field(default_factory=ToleranceDefaults)
    gripper: GripperSettings = field(default_factory=GripperSettings)
    config: str = ""

    def with_changes(self, **changes: Any) -> MujocoDriverSettings:
        """A copy with some fields replaced."""
        return replace(self, **changes)

    @classmethod
    def from_config(
        cls,
        config: str | ResolvedConfig,
        workspace: Workspace | None = None,
        **overrides: Any,
    ) -> MujocoDriverSettings:
        """Settings for config package ``config`` (a name, resolved in ``workspace``, or a resolved config).

        Raises:
            ConfigError: the config cannot be resolved or has no ``hardware.simulation.mujoco_model``.
        """
        from kinema.config import resolve_config
        from kinema.config.cell import CellSettings

        resolved = resolve_config(config, workspace, check_files=False) if isinstance(config, str) else config
        model_path = resolved.mujoco_model_path
        if model_path is None:
            raise ConfigError(
                f"config {resolved.name!r} has no MuJoCo scene: set hardware.simulation.mujoco_model "
                "({package, path}), or MoveIt Pro's hardware.robot_description.urdf_params mujoco_model, "
                "to simulate it",
                location=resolved.location_of("hardware"),
            )
        cell = CellSettings.from_config(resolved)
        keyframe = resolved.mujoco_keyframe
        active = [c.name for c in cell.controllers.values() if c.active]
        inactive = [c.name for c in cell.controllers.values() if not c.active]
        sensor = cell.force_torque_sensor
        settings = cls(
            model_path=model_path,
            keyframe=keyframe,
            active_controllers=tuple(active) if cell.controllers else DEFAULT_CONTROLLERS,
            inactive_controllers=tuple(inactive),
            controllers=dict(cell.controllers),
            gripper_joint=cell.gripper.joint if cell.gripper else None,
            force_torque_sensor=sensor.name if sensor else None,
            control_site=sensor.control_site if sensor else "",
            config=resolved.name,
        )
        return settings.with_changes(**overrides) if overrides else settings
