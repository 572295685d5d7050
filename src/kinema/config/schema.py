"""The config.yaml schema: MoveIt Pro's keys, their types, and which of them Kinema uses.

Validation is per file, before inheritance: a value of the wrong type is an error that names the file,
the line, the key path and (for a mapping) the valid keys. A key the schema does not know is kept in the
data and reported as a notice (shown in verbose mode), never fatal, so MoveIt Pro configs with keys Kinema
has no use for still load. Keys the schema knows but Kinema does not act on (``ros_global_params``,
legacy launch-file keys, ...) are kept and noted the same way.

Kinema extension: ``hardware.simulation`` (``mujoco_model`` file ref, ``mujoco_keyframe`` name) says
which MuJoCo scene simulates the robot; MoveIt Pro passes the same through xacro ``urdf_params``.

What must be present is checked after inheritance (:data:`REQUIRED`), because a child config usually
sets only what it changes.
"""

from __future__ import annotations

from collections.abc import Hashable, Mapping
from dataclasses import dataclass, field
from typing import Any

from kinema.config.refs import DIR_REF_KEYS, FILE_REF_KEYS, is_ref, looks_like_ref
from kinema.config.yamlsource import YamlDocument
from kinema.errors import ConfigError, did_you_mean


@dataclass(frozen=True)
class Field:
    """One key of the schema.

    Attributes:
        kind: ``str``, ``bool``, ``number``, ``map`` (known ``keys``), ``map_of`` (any key, each value
            of ``item``), ``list_of`` (items of ``item``), ``file``/``dir`` (a reference that must name a
            file/folder), ``params`` (xacro ``urdf_params``: a list of one-key maps), ``any``.
        used: Kinema acts on this key (references of used keys are checked to exist at resolution).
        keys: the known keys of a ``map``.
        item: the value schema of ``map_of``/``list_of``.
    """

    kind: str
    used: bool = False
    keys: Mapping[str, Field] = field(default_factory=dict)
    item: Field | None = None


def _map(used: bool = False, **keys: Field) -> Field:
    return Field("map", used=used, keys=keys)


_STR = Field("str")
_BOOL = Field("bool")
_NUMBER = Field("number")
_FILE = Field("file")
_STR_LIST = Field("list_of", item=_STR)

SCHEMA = _map(
    used=True,
    based_on_package=Field("str", used=True),
    runtime_launch_file=_FILE,
    hardware=_map(
        used=True,
        launch_control_node=_BOOL,
        launch_robot_state_publisher=_BOOL,
        additional_driver_launch_file=_FILE,
        additional_agent_launch_file=_FILE,
        robot_description=_map(
            used=True,
            urdf=Field("file", used=True),
            srdf=Field("file", used=True),
            urdf_params=Field("params"),
        ),
        simulation=_map(
            used=True,
            mujoco_model=Field("file", used=True),
            mujoco_keyframe=Field("str", used=True),
        ),
        simulated=_BOOL,
        robot_driver_persist_launch_file=_FILE,
        simulated_robot_driver_persist_launch_file=_FILE,
        simulated_hardware_launch_file=_FILE,
        robot_driver_restart_launch_file=_FILE,
        simulated_robot_driver_restart_launch_file=_FILE,
        hardware_launch_file=_FILE,
        type=_STR,
        ip=_STR,
        camera_config_file=_FILE,
        launch_cameras_when_simulated=_BOOL,
    ),
    ros_global_params=_map(use_sim_time=_BOOL),
    moveit_params=_map(
        used=True,
        joint_group_name=Field("str", used=True),
        joint_limits=Field("file", used=True),
        kinematics=_FILE,
        sensors_3d=_FILE,
        pose_jog=_FILE,
        joint_jog=_FILE,
        ompl_planning=_FILE,
        pilz_planning=_FILE,
        pilz_cartesian_limits=_FILE,
        stomp_planning=_FILE,
        servo=_FILE,
        servo_kinematics=_FILE,
        servo_joint_limits=_FILE,
        publish=_map(
            planning_scene=_BOOL, geometry_updates=_BOOL, state_updates=_BOOL, transforms_updates=_BOOL
        ),
        trajectory_execution=_map(
            manage_controllers=_BOOL,
            allowed_execution_duration_scaling=_NUMBER,
            allowed_goal_duration_margin=_NUMBER,
            allowed_start_tolerance=_NUMBER,
        ),
    ),
    ros2_control=_map(
        used=True,
        config=Field("file", used=True),
        controllers_active_at_startup=Field("list_of", used=True, item=_STR),
        controllers_inactive_at_startup=Field("list_of", used=True, item=_STR),
        controllers_not_managed=_STR_LIST,
        controller_shared_topics=Field("list_of", item=Field("any")),
    ),
    objectives=_map(
        used=True,
        behavior_loader_plugins=Field("map_of", used=True, item=Field("list_of", used=True, item=_STR)),
        objective_library_paths=Field("map_of", used=True, item=Field("dir", used=True)),
        waypoints_file=Field("file", used=True),
    ),
    # Kinema: the robot's tool frame, gripper, F/T sensor, controllers and default camera
    # (kinema.config.cell).
    robot=_map(
        used=True,
        tool_frame=Field("str", used=True),
        default_camera=Field("str", used=True),
        gripper=_map(
            used=True,
            controller=Field("str", used=True),
            joint=Field("str", used=True),
            open_position=Field("number", used=True),
            closed_position=Field("number", used=True),
        ),
        force_torque_sensor=_map(
            used=True,
            name=Field("str", used=True),
            frame=Field("str", used=True),
            control_site=Field("str", used=True),
        ),
        controllers=Field(
            "map_of",
            used=True,
            item=_map(used=True, type=Field("str", used=True), joints=Field("list_of", used=True, item=_STR)),
        ),
    ),
    optional_feature_params=Field("any"),
    octomap_manager=_map(input_point_cloud_topic=_STR),
)

#: Key paths that must be set somewhere in the inheritance chain.
REQUIRED: tuple[tuple[str, ...], ...] = (
    ("hardware", "robot_description", "urdf"),
    ("hardware", "robot_description", "srdf"),
    ("objectives", "behavior_loader_plugins"),
    ("objectives", "objective_library_paths"),
)

_PYTHON_TYPES: dict[str, type | tuple[type, ...]] = {"str": str, "bool": bool, "number": (int, float)}
_KIND_TEXT = {
    "str": "a string",
    "bool": "true or false",
    "number": "a number",
    "map": "a mapping",
    "map_of": "a mapping",
    "list_of": "a list",
    "file": "a file reference {package: NAME, path: PATH}",
    "dir": "a folder reference {package_name: NAME, relative_path: PATH}",
    "params": "a list of one-key mappings (- name: value)",
}


def dotted(path: tuple[Hashable, ...]) -> str:
    """Render a key path as ``a.b[2].c``."""
    out = ""
    for part in path:
        if isinstance(part, int) and not isinstance(part, bool):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out or "(top level)"


def field_at(path: tuple[Hashable, ...]) -> Field | None:
    """Return the schema of the key at ``path`` (indices are ignored), or None when it is unknown."""
    current: Field | None = SCHEMA
    for part in path:
        if current is None:
            return None
        if isinstance(part, int) and not isinstance(part, bool):
            current = current.item if current.kind in ("list_of", "params") else None
        elif current.kind == "map":
            current = current.keys.get(str(part))
        elif current.kind == "map_of":
            current = current.item
        else:
            return None
    return current


# Notices that start so (after ``file:line: ``) name a key no schema knows: a typo, most of the time.
UNKNOWN_KEY = "unknown key"


def is_unknown_key_notice(notice: str) -> bool:
    """Whether a notice of :func:`validate_document` names an unknown key (shown without ``-v``)."""
    return f": {UNKNOWN_KEY} " in notice


def validate_document(document: YamlDocument, package: str) -> list[str]:
    """Check one config.yaml against the schema.

    Args:
        document: the parsed file.
        package: the package it belongs to (for messages).

    Returns:
        Notices about unknown keys and keys Kinema does not use, each starting with ``file:line:``.

    Raises:
        ConfigError: a value has the wrong type; the message names file, line, key and the valid keys.
    """
    if document.data is None:
        document.data = {}
    notices: list[str] = []
    _check(document, (), document.data, SCHEMA, notices)
    return notices


def _check(
    document: YamlDocument, path: tuple[Hashable, ...], value: Any, spec: Field, notices: list[str]
) -> None:
    kind = spec.kind
    if kind == "any":
        return
    if kind in ("file", "dir"):
        _check_ref(document, path, value, kind)
        return
    if kind == "map":
        _expect(document, path, value, dict, kind)
        for key, child in value.items():
            child_spec = spec.keys.get(key) if isinstance(key, str) else None
            if child_spec is None:
                hint = did_you_mean(str(key), spec.keys)
                where = dotted(path) if path else "the top level"
                notices.append(
                    f"{document.location((*path, key))}: {UNKNOWN_KEY} {key!r} in {where} is kept but not "
                    f"used by Kinema ({hint})"
                )
                continue
            if spec.used and not child_spec.used:  # inside an unused section, its own notice suffices
                notices.append(
                    f"{document.location((*path, key))}: {dotted((*path, key))} "
                    "is read but not used by Kinema"
                )
            _check(document, (*path, key), child, child_spec, notices)
        return
    if kind == "map_of":
        _expect(document, path, value, dict, kind)
        assert spec.item is not None
        for key, child in value.items():
            _check(document, (*path, key), child, spec.item, notices)
        return
    if kind == "list_of":
        if value is None:  # `key:` with nothing after it is an empty list in MoveIt Pro's files
            return
        _expect(document, path, value, list, kind)
        assert spec.item is not None
        for index, item in enumerate(value):
            _check(document, (*path, index), item, spec.item, notices)
        return
    if kind == "params":
        _check_params(document, path, value)
        return
    expected = _PYTHON_TYPES[kind]
    if kind == "number" and isinstance(value, bool):
        _fail(document, path, value, kind)
    _expect(document, path, value, expected, kind)


def _expect(
    document: YamlDocument,
    path: tuple[Hashable, ...],
    value: Any,
    expected: type | tuple[type, ...],
    kind: str,
) -> None:
    if not isinstance(value, expected):
        _fail(document, path, value, kind)


def _fail(document: YamlDocument, path: tuple[Hashable, ...], value: Any, kind: str) -> None:
    spec = field_at(path)
    message = f"{dotted(path)} must be {_KIND_TEXT[kind]}, not {_describe(value)}"
    if spec is not None and spec.kind == "map" and spec.keys:
        message += f"; valid keys: {', '.join(spec.keys)}"
    raise ConfigError(message, location=document.location(path))


def _describe(value: Any) -> str:
    if value is None:
        return "nothing (null)"
    if isinstance(value, bool):
        return f"the boolean {str(value).lower()}"
    if isinstance(value, dict):
        return f"a mapping with keys {', '.join(map(str, value)) or '(none)'}"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, (int, float)):
        return f"the number {value}"
    return f"the string {value!r}"


def _check_ref(document: YamlDocument, path: tuple[Hashable, ...], value: Any, kind: str) -> None:
    shape = "{package: NAME, path: PATH} or {package_name: NAME, relative_path: PATH}"
    if not isinstance(value, dict):
        raise ConfigError(
            f"{dotted(path)} must be a reference {shape}, not {_describe(value)}",
            location=document.location(path),
        )
    if not is_ref(value):
        keys = set(map(str, value))
        valid = FILE_REF_KEYS if keys & FILE_REF_KEYS or not keys & DIR_REF_KEYS else DIR_REF_KEYS
        wrong = sorted(keys - valid) if keys - valid else []
        missing = sorted(valid - keys)
        detail = []
        if wrong:
            detail.append(f"unexpected {', '.join(wrong)}")
        if missing:
            detail.append(f"missing {', '.join(missing)}")
        raise ConfigError(
            f"{dotted(path)} must be a reference {shape} ({'; '.join(detail)}); valid keys: "
            f"{', '.join(sorted(valid))}",
            location=document.location(path),
        )
    for key, item in value.items():
        if not isinstance(item, str) or not item.strip():
            raise ConfigError(
                f"{dotted((*path, key))} must be a non-empty string, not {_describe(item)}",
                location=document.location((*path, key)),
            )


def _check_params(document: YamlDocument, path: tuple[Hashable, ...], value: Any) -> None:
    if value is None:
        return
    _expect(document, path, value, list, "params")
    for index, item in enumerate(value):
        if not isinstance(item, dict) or len(item) != 1:
            raise ConfigError(
                f"{dotted((*path, index))} must be a one-key mapping like `- name: value`, "
                f"not {_describe(item)}",
                location=document.location((*path, index)),
            )
        ((key, param),) = item.items()
        if isinstance(param, dict) and looks_like_ref(param):
            _check_ref(document, (*path, index, key), param, "file")
        elif isinstance(param, (dict, list)):
            raise ConfigError(
                f"{dotted((*path, index, key))} must be a value or a file reference, not {_describe(param)}",
                location=document.location((*path, index, key)),
            )
