"""A cell's robot-specific settings: planning group, tool frame, gripper, F/T sensor, controllers, camera.

Every name a behavior, a core subtree or the simulation driver needs about the robot comes from here, and
this reads them from the config package (never from a constant in code). The sources, most specific
first:

1. ``config.yaml``'s Kinema section ``robot:`` (lab_sim's values here, as an example; nothing in code
   defaults to them)::

       robot:
         tool_frame: grasp_link                  # the frame Cartesian moves and IK place (a URDF link)
         default_camera: wrist_camera            # the camera image/cloud behaviors read by default
         gripper:
           controller: robotiq_gripper_controller   # serves /<controller>/gripper_cmd
           joint: robotiq_85_left_knuckle_joint
           open_position: 0.0
           closed_position: 0.7929
         force_torque_sensor:
           name: tcp_fts_sensor                  # the sensor (the MuJoCo site carrying <name>_force/_torque)
           frame: tool0
           control_site: grasp_site              # the velocity-force controller's control frame (a site)
         controllers:                            # only where the ros2_control yaml does not say
           my_arm_controller:
             type: joint_trajectory_controller/JointTrajectoryController
             joints: [joint_1, joint_2]

2. MoveIt Pro's ros2_control yaml (``ros2_control.config``): each controller's ``type`` under
   ``controller_manager.ros__parameters``, its ``joints``/``joint``, and the F/T broadcaster's
   ``sensor_name``/``frame_id``;
3. the SRDF: the planning group's tip link as tool frame when none is given.

The default planning group is ``moveit_params.joint_group_name``. Which controllers run is
``ros2_control.controllers_active_at_startup`` / ``controllers_inactive_at_startup``.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from kinema.errors import ConfigError, did_you_mean

if TYPE_CHECKING:
    from kinema.config.inheritance import ResolvedConfig

# ros2_control controller types the MuJoCo driver simulates.
JOINT_STATE_BROADCASTER = "joint_state_broadcaster/JointStateBroadcaster"
JOINT_TRAJECTORY_CONTROLLER = "joint_trajectory_controller/JointTrajectoryController"
GRIPPER_ACTION_CONTROLLER = "position_controllers/GripperActionController"
FORCE_TORQUE_SENSOR_BROADCASTER = "force_torque_sensor_broadcaster/ForceTorqueSensorBroadcaster"
ADMITTANCE_CONTROLLER = "joint_trajectory_admittance_controller/JointTrajectoryAdmittanceController"
VELOCITY_FORCE_CONTROLLER = "velocity_force_controller/VelocityForceController"

#: Other spellings of the same types (ROS 2 distributions moved the gripper controller).
TYPE_ALIASES = {
    "parallel_gripper_action_controller/GripperActionController": GRIPPER_ACTION_CONTROLLER,
    "gripper_controllers/GripperActionController": GRIPPER_ACTION_CONTROLLER,
}

SIMULATED_TYPES = (
    JOINT_STATE_BROADCASTER,
    JOINT_TRAJECTORY_CONTROLLER,
    GRIPPER_ACTION_CONTROLLER,
    FORCE_TORQUE_SENSOR_BROADCASTER,
    ADMITTANCE_CONTROLLER,
    VELOCITY_FORCE_CONTROLLER,
)

# ros2_control's own conventional controller names, whose type a config need not spell out. These name
# no robot: they are what ros2_control's and MoveIt Pro's examples call these controllers.
CONVENTIONAL_TYPES = {
    "joint_state_broadcaster": JOINT_STATE_BROADCASTER,
    "joint_trajectory_controller": JOINT_TRAJECTORY_CONTROLLER,
    "force_torque_sensor_broadcaster": FORCE_TORQUE_SENSOR_BROADCASTER,
    "joint_trajectory_admittance_controller": ADMITTANCE_CONTROLLER,
    "velocity_force_controller": VELOCITY_FORCE_CONTROLLER,
}


@dataclass(frozen=True)
class ControllerSpec:
    """One ros2_control controller as the config describes it.

    Attributes:
        name: the controller's name (its topics and actions are under ``/<name>/``).
        type: the ros2_control type, e.g. ``joint_trajectory_controller/JointTrajectoryController``.
        joints: the joints it commands (empty: the driver decides, e.g. every arm joint).
        active: started with the cell (``controllers_active_at_startup``), else loaded inactive.
        parameters: its ``ros__parameters`` in MoveIt Pro's ros2_control yaml (empty without one); the
            driver reads the ones it simulates (e.g. the admittance controller's
            ``default_absolute_force_torque_threshold``).
    """

    name: str
    type: str
    joints: tuple[str, ...] = ()
    active: bool = True
    parameters: Mapping[str, Any] = field(default_factory=dict, compare=False)


@dataclass(frozen=True)
class GripperConfig:
    """The gripper: the joint its controller commands and where open and closed are.

    Attributes:
        controller: the GripperActionController's name.
        joint: the joint it commands (the leader; mimic joints follow).
        open_position: the joint's position when open (m or rad).
        closed_position: the joint's position when fully closed.
    """

    controller: str
    joint: str
    open_position: float
    closed_position: float

    @property
    def action(self) -> str:
        """The ``control_msgs/action/GripperCommand`` action: ``/<controller>/gripper_cmd``."""
        return f"/{self.controller}/gripper_cmd"


@dataclass(frozen=True)
class ForceTorqueSensorConfig:
    """The wrist force/torque sensor.

    Attributes:
        name: the sensor's name (in simulation the MuJoCo site carrying ``<name>_force``/``_torque``).
        frame: the link the wrench is expressed in.
        control_site: the MuJoCo site of the velocity-force controller's control frame ("" for none).
    """

    name: str
    frame: str = ""
    control_site: str = ""


@dataclass(frozen=True)
class CellSettings:
    """Robot-specific names and values of one cell, all from its config package.

    Attributes:
        planning_group: the default planning group (``moveit_params.joint_group_name``), None if unset.
        tool_frame: the frame Cartesian moves and IK place by default, None if unknown.
        gripper: the gripper, None for a robot without one.
        force_torque_sensor: the F/T sensor, None without one.
        controllers: every controller the config names, by name, in config order.
        default_camera: the camera perception behaviors read when no topic is given, None for none.
        config: the config package these came from.
    """

    planning_group: str | None = None
    tool_frame: str | None = None
    gripper: GripperConfig | None = None
    force_torque_sensor: ForceTorqueSensorConfig | None = None
    controllers: Mapping[str, ControllerSpec] = field(default_factory=dict)
    default_camera: str | None = None
    config: str = ""

    def value(self, key: str) -> Any:
        """A setting by its :class:`CellValue` key (see :data:`CELL_VALUE_KEYS`), None when unset."""
        if key not in CELL_VALUE_KEYS:
            raise KeyError(f"unknown cell setting {key!r}; {did_you_mean(key, CELL_VALUE_KEYS)}")
        return CELL_VALUE_KEYS[key][0](self)

    def controllers_of_type(self, type_name: str) -> list[ControllerSpec]:
        """The controllers of one ros2_control type, in config order."""
        return [c for c in self.controllers.values() if c.type == type_name]

    @classmethod
    def from_config(cls, resolved: ResolvedConfig) -> CellSettings:
        """Read the settings of a resolved config package.

        Raises:
            ConfigError: a value has the wrong type, or a controller's type is unknown and not given;
                the message names config.yaml's line.
        """
        robot = resolved.get("robot") or {}
        if not isinstance(robot, Mapping):
            raise ConfigError("robot must be a mapping", location=resolved.location_of("robot"))
        control = _ros2_control_yaml(resolved)
        controllers = _controllers(resolved, robot, control)
        gripper = _gripper(resolved, robot, control, controllers)
        sensor = _force_torque_sensor(resolved, robot, control)
        group = resolved.get("moveit_params.joint_group_name")
        tool = robot.get("tool_frame")
        camera = robot.get("default_camera")
        return cls(
            planning_group=str(group) if group else None,
            tool_frame=str(tool) if tool else None,
            gripper=gripper,
            force_torque_sensor=sensor,
            controllers=controllers,
            default_camera=str(camera) if camera else None,
            config=resolved.name,
        )


#: The settings a behavior port or a subtree may take its default from: key -> (getter, where it is set).
CELL_VALUE_KEYS: dict[str, tuple[Any, str]] = {
    "planning_group": (lambda c: c.planning_group, "moveit_params.joint_group_name"),
    "tool_frame": (lambda c: c.tool_frame, "robot.tool_frame"),
    "gripper_action": (lambda c: c.gripper.action if c.gripper else None, "robot.gripper.controller"),
    "gripper_open_position": (
        lambda c: c.gripper.open_position if c.gripper else None,
        "robot.gripper.open_position",
    ),
    "gripper_closed_position": (
        lambda c: c.gripper.closed_position if c.gripper else None,
        "robot.gripper.closed_position",
    ),
    "admittance_controller_action": (
        lambda c: next(
            (
                f"/{spec.name}/follow_joint_trajectory"
                for spec in c.controllers_of_type(ADMITTANCE_CONTROLLER)
            ),
            None,
        ),
        "ros2_control (a controller of type " + ADMITTANCE_CONTROLLER + ")",
    ),
    "trajectory_action": (
        lambda c: next(
            (
                f"/{spec.name}/follow_joint_trajectory"
                for spec in c.controllers_of_type(JOINT_TRAJECTORY_CONTROLLER)
            ),
            None,
        ),
        "ros2_control controllers (the first JointTrajectoryController)",
    ),
    "camera_color_topic": (
        lambda c: f"/{c.default_camera}/color" if c.default_camera else None,
        "robot.default_camera",
    ),
    "camera_points_topic": (
        lambda c: f"/{c.default_camera}/points" if c.default_camera else None,
        "robot.default_camera",
    ),
    "camera_info_topic": (
        lambda c: f"/{c.default_camera}/camera_info" if c.default_camera else None,
        "robot.default_camera",
    ),
}


def setting_key_path(key: str) -> str:
    """Where in config.yaml the cell value ``key`` is set (for messages)."""
    return str(CELL_VALUE_KEYS[key][1])


def _ros2_control_yaml(resolved: ResolvedConfig) -> dict[str, Any]:
    """MoveIt Pro's ros2_control yaml (``ros2_control.config``), or ``{}``."""
    if resolved.get("ros2_control.config") is None:
        return {}
    from kinema.config.yamlsource import load_yaml_file

    path = resolved.resolve_file("ros2_control.config", kind="file")
    document = load_yaml_file(path)
    data = document.data if isinstance(document.data, dict) else {}
    return data


def _params(control: dict[str, Any], name: str) -> dict[str, Any]:
    entry = control.get(name)
    params = entry.get("ros__parameters") if isinstance(entry, dict) else None
    return params if isinstance(params, dict) else {}


def _controllers(
    resolved: ResolvedConfig, robot: Mapping[str, Any], control: dict[str, Any]
) -> dict[str, ControllerSpec]:
    declared_types = _params(control, "controller_manager")
    own = robot.get("controllers") or {}
    if not isinstance(own, Mapping):
        raise ConfigError(
            "robot.controllers must map controller names to {type, joints}",
            location=resolved.location_of("robot.controllers"),
        )
    active = [str(n).lstrip("/") for n in resolved.get("ros2_control.controllers_active_at_startup") or ()]
    inactive = [
        str(n).lstrip("/") for n in resolved.get("ros2_control.controllers_inactive_at_startup") or ()
    ]
    gripper = robot.get("gripper") if isinstance(robot.get("gripper"), Mapping) else {}
    names = list(dict.fromkeys([*active, *inactive, *(str(n) for n in own)]))
    out: dict[str, ControllerSpec] = {}
    for name in names:
        entry = own.get(name) or {}
        if not isinstance(entry, Mapping):
            raise ConfigError(
                f"robot.controllers.{name} must be a mapping {{type, joints}}",
                location=resolved.location_of(("robot", "controllers", name)),
            )
        type_name = entry.get("type")
        if not type_name and isinstance(declared_types.get(name), dict):
            type_name = declared_types[name].get("type")
        if not type_name and gripper and gripper.get("controller") == name:
            type_name = GRIPPER_ACTION_CONTROLLER
        type_name = str(type_name or CONVENTIONAL_TYPES.get(name, ""))
        type_name = TYPE_ALIASES.get(type_name, type_name)
        if not type_name:
            raise ConfigError(
                f"controller {name!r} has no type: give robot.controllers.{name}.type (one of "
                f"{', '.join(SIMULATED_TYPES)}), or name it in the ros2_control yaml (ros2_control.config)",
                location=resolved.location_of("ros2_control"),
            )
        params = _params(control, name)
        joints = entry.get("joints") or params.get("joints") or ()
        if not joints and params.get("joint"):
            joints = [params["joint"]]
        if isinstance(joints, str):
            joints = [joints]
        out[name] = ControllerSpec(
            name=name,
            type=type_name,
            joints=tuple(str(j) for j in joints),
            active=name not in inactive,
            parameters=params,
        )
    return out


def _number(resolved: ResolvedConfig, value: Any, key: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(f"{key} must be a number, got {value!r}", location=resolved.location_of(key))
    return float(value)


def _gripper(
    resolved: ResolvedConfig,
    robot: Mapping[str, Any],
    control: dict[str, Any],
    controllers: Mapping[str, ControllerSpec],
) -> GripperConfig | None:
    entry = robot.get("gripper")
    grippers = [c for c in controllers.values() if c.type == GRIPPER_ACTION_CONTROLLER]
    if entry is None:
        if not grippers:
            return None
        found = _gripper_from_srdf(resolved, control, grippers[0]) if len(grippers) == 1 else None
        if found is not None:
            return found
        raise ConfigError(
            f"controller {grippers[0].name!r} is a gripper controller, but robot.gripper does not say where "
            "open and closed are: add robot.gripper {controller, joint, open_position, closed_position}, "
            "or group states 'open' and 'close' of an SRDF group holding its joint",
            location=resolved.location_of("ros2_control"),
        )
    if not isinstance(entry, Mapping):
        raise ConfigError(
            "robot.gripper must be a mapping {controller, joint, open_position, closed_position}",
            location=resolved.location_of("robot.gripper"),
        )
    missing = [k for k in ("controller", "open_position", "closed_position") if entry.get(k) is None]
    if missing:
        raise ConfigError(
            f"robot.gripper lacks {', '.join(missing)} (it needs controller, joint, open_position, "
            "closed_position)",
            location=resolved.location_of("robot.gripper"),
        )
    controller = str(entry["controller"])
    joint = entry.get("joint") or _params(control, controller).get("joint")
    if not joint:
        raise ConfigError(
            f"robot.gripper.joint is not set, and the ros2_control yaml gives controller {controller!r} no "
            "joint",
            location=resolved.location_of("robot.gripper"),
        )
    return GripperConfig(
        controller=controller,
        joint=str(joint),
        open_position=_number(resolved, entry["open_position"], "robot.gripper.open_position"),
        closed_position=_number(resolved, entry["closed_position"], "robot.gripper.closed_position"),
    )


def _gripper_from_srdf(
    resolved: ResolvedConfig, control: dict[str, Any], controller: ControllerSpec
) -> GripperConfig | None:
    """A MoveIt Pro config's gripper, with no ``robot.gripper``: the controller's joint (ros2_control
    yaml), open and closed from the SRDF group states ``open`` and ``close`` (or ``closed``) of a group
    holding that joint, as MoveIt Pro's own gripper objectives move it. None when either is missing."""
    from kinema.errors import KinemaError
    from kinema.motion.srdf import parse_srdf

    joint = _params(control, controller.name).get("joint") or (
        controller.joints[0] if controller.joints else ""
    )
    if not joint:
        return None
    try:
        opened, closed = parse_srdf(resolved.srdf_path).gripper_positions(str(joint))
    except KinemaError:
        return None  # no SRDF, or one that does not read: robot_check and the planner say why
    if opened is None or closed is None:
        return None
    return GripperConfig(
        controller=controller.name, joint=str(joint), open_position=opened, closed_position=closed
    )


def _force_torque_sensor(
    resolved: ResolvedConfig, robot: Mapping[str, Any], control: dict[str, Any]
) -> ForceTorqueSensorConfig | None:
    entry = robot.get("force_torque_sensor")
    params = _params(control, "force_torque_sensor_broadcaster")
    if entry is None and not params.get("sensor_name"):
        return None
    entry = entry if isinstance(entry, Mapping) else {}
    name = entry.get("name") or params.get("sensor_name")
    if not name:
        raise ConfigError(
            "robot.force_torque_sensor needs a name (the sensor; in simulation the MuJoCo site)",
            location=resolved.location_of("robot.force_torque_sensor"),
        )
    return ForceTorqueSensorConfig(
        name=str(name),
        frame=str(entry.get("frame") or params.get("frame_id") or ""),
        control_site=str(entry.get("control_site") or ""),
    )


# A subtree port default that is (or holds) the running config's value, written in a <TreeNodesModel> as
# ``default="$(config moveit_params.joint_group_name)"`` or
# ``default="/$(config robot.default_camera)/color"``. Kinema's core subtrees use it, so they name no robot's
# group, link or camera.
_CONFIG_DEFAULT = re.compile(r"\$\(config\s+([A-Za-z0-9_.]+)\)")


def config_default_key(text: str | None) -> str | None:
    """The config key a ``$(config KEY)`` port default names (the first), or None for any other default."""
    found = _CONFIG_DEFAULT.search(text) if text else None
    return found.group(1) if found else None


def config_default_value(text: str, resolved: ResolvedConfig | None) -> str:
    """``text`` with each ``$(config KEY)`` replaced by the config's value; ``""`` when one is unset."""
    values = [resolved.get(key) if resolved is not None else None for key in _CONFIG_DEFAULT.findall(text)]
    if any(value is None for value in values):
        return ""
    found = iter(values)
    return _CONFIG_DEFAULT.sub(lambda _match: str(next(found)), text)


def substitute_config_defaults(subtree_models: Mapping[str, Any], resolved: ResolvedConfig | None) -> None:
    """Replace each ``$(config KEY)`` in the subtree models' port defaults with the config's value at KEY.

    A key the config does not set leaves the port without a default, so a caller that does not give the
    port fails with the engine's "mandatory port" message; without a config (``resolved`` None) the same.
    """
    for model in subtree_models.values():
        for port in model.ports.values():
            if config_default_key(port.default_str) is None:
                continue
            text = config_default_value(port.default_str.strip(), resolved)
            port.default = text
            port.default_str = text
