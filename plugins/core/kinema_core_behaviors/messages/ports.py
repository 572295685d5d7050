"""Declaring and reading ports, the one way every core behavior family does it.

Declare message-typed ports with :func:`message_input` / :func:`message_output` (and the vector forms),
which give the port the shared type object of its ROS type (:mod:`.types`) and say the type in the
description. Read ports with :func:`read_input` (any port) or :func:`read_message` (a message of the
port's type): a missing, empty or wrong value raises :class:`PortValueError`, whose message names the
behavior, the port, the value it got and what would have been valid. Behaviors wrap their ``tick`` /
``do_work`` in :func:`fails_on_bad_input`, which turns that error into a failure toast and FAILURE, so bad
input never raises out of the tree.

Conversions between messages and numpy live in :mod:`.conversions`; this module only moves values
between the blackboard and the behavior.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from kinema.behaviors import NodeStatus, PortInfo, bidirectional_port, input_port, output_port
from kinema.bt.errors import BTError
from kinema.bt.ports import NO_DEFAULT
from kinema.errors import ObjectiveError

from .types import message_type, ros_type_of_port_type

F = TypeVar("F", bound=Callable[..., Any])

# Where a user gets a value of a message type; named in errors as the valid alternatives.
PRODUCERS: dict[str, str] = {
    "geometry_msgs/msg/PoseStamped": "CreatePoseStamped, TransformPose, GetElementOfVector of a pose vector",
    "geometry_msgs/msg/Pose": "UnpackPoseStampedMessage",
    "geometry_msgs/msg/Point": "UnpackPoseMessage",
    "geometry_msgs/msg/TwistStamped": "CreateTwistStamped",
    "geometry_msgs/msg/WrenchStamped": "CreateWrenchStamped",
    "std_msgs/msg/String": "CreateStringMessage",
    "sensor_msgs/msg/JointState": "GetJointState, RetrieveWaypoint, UnpackRobotStateMessage",
    "moveit_studio_agent_msgs/msg/RobotJointState": "CreateRobotState, LoadRobotJointStateFromYaml",
    "trajectory_msgs/msg/JointTrajectory": "PlanToJointGoal, PlanCartesianPath, LoadJointTrajectoryFromYaml",
    "moveit_msgs/msg/CollisionObject": "UnpackGraspableObjectMessage",
    "sensor_msgs/msg/Image": "GetImage, LoadImageFromFile",
    "sensor_msgs/msg/CameraInfo": "GetCameraInfo",
    "sensor_msgs/msg/PointCloud2": "GetPointCloud",
    "vision_msgs/msg/Detection3DArray": "DetectAprilTags",
}


class PortValueError(ObjectiveError):
    """A port's value is missing or unusable; the message names the port, the value and the alternatives."""


def _describe(description: str, ros_type: str, vector: bool) -> str:
    shown = f"std::vector<{ros_type}>" if vector else ros_type
    return f"{description} ({shown})" if description else shown


def message_input(name: str, ros_type: str, default: Any = NO_DEFAULT, description: str = "") -> PortInfo:
    """An input port holding one message of ``ros_type``."""
    return input_port(name, message_type(ros_type), default, _describe(description, ros_type, False))


def message_output(name: str, ros_type: str, default: Any = NO_DEFAULT, description: str = "") -> PortInfo:
    """An output port holding one message of ``ros_type`` (default: a ``{key}`` pointer)."""
    return output_port(name, message_type(ros_type), default, _describe(description, ros_type, False))


def message_vector_input(
    name: str, ros_type: str, default: Any = NO_DEFAULT, description: str = ""
) -> PortInfo:
    """An input port holding a vector of messages of ``ros_type``."""
    return input_port(name, list[message_type(ros_type)], default, _describe(description, ros_type, True))  # type: ignore[misc]


def message_vector_output(
    name: str, ros_type: str, default: Any = NO_DEFAULT, description: str = ""
) -> PortInfo:
    """An output port holding a vector of messages of ``ros_type``."""
    return output_port(name, list[message_type(ros_type)], default, _describe(description, ros_type, True))  # type: ignore[misc]


def message_vector_inout(
    name: str, ros_type: str, default: Any = NO_DEFAULT, description: str = ""
) -> PortInfo:
    """An input/output port holding a vector of messages of ``ros_type``."""
    return bidirectional_port(
        name,
        list[message_type(ros_type)],
        default,
        _describe(description, ros_type, True),  # type: ignore[misc]
    )


def speed_scale_ports(
    velocity: str | None = "velocity_scale_factor", acceleration: str | None = "acceleration_scale_factor"
) -> list[PortInfo]:
    """The ports scaling a motion's speed below the joints' limits, declared once for every behavior that
    times a motion (MoveIt Pro names them per behavior: ``velocity_scale`` on SetupMTCMoveAlongFrameAxis);
    a name given as None is left out."""
    ports = []
    if velocity:
        ports.append(input_port(velocity, float, 1.0, "Fraction of the joints' velocity limits, (0, 1]."))
    if acceleration:
        ports.append(
            input_port(acceleration, float, 1.0, "Fraction of the joints' acceleration limits, (0, 1].")
        )
    return ports


def shown(value: Any, limit: int = 80) -> str:
    """A value as an error message shows it: its type and a short text form."""
    ros_type = getattr(value, "__msgtype__", None)
    if isinstance(ros_type, str):
        return f"a {ros_type} message"
    if isinstance(value, list):
        inner = {getattr(v, "__msgtype__", type(v).__name__) for v in value}
        return f"a vector of {len(value)} ({', '.join(sorted(inner)) or 'empty'})"
    text = repr(value)
    return f"{type(value).__name__} {text[:limit]}{'…' if len(text) > limit else ''}"


def _who(node: Any) -> str:
    behavior = getattr(node, "registration_id", type(node).__name__)
    path = getattr(node, "full_path", "")
    return f"{behavior} '{path}'" if path and path != behavior else str(behavior)


def port_error(node: Any, port: str, problem: str, alternatives: str = "") -> PortValueError:
    """A :class:`PortValueError`: ``Behavior 'path': port [p] problem; alternatives``."""
    tail = f"; {alternatives}" if alternatives else ""
    return PortValueError(f"{_who(node)}: port [{port}] {problem}{tail}")


def _expected(node: Any, port: str) -> str:
    manifest = getattr(getattr(node, "config", None), "manifest", None)
    info = manifest.ports.get(port) if manifest is not None else None
    if info is None:
        return ""
    ros_type = ros_type_of_port_type(info.type)
    if ros_type is not None:
        producers = PRODUCERS.get(ros_type)
        return f"expected a {ros_type}" + (f" (from {producers})" if producers else "")
    if not info.strongly_typed:
        return ""
    return f"expected {info.type_name}"


def read_input(node: Any, port: str, type: Any = None) -> Any:
    """The value of input port ``port`` (converted to ``type`` or the declared type).

    Raises:
        PortValueError: the port has no value or the value has another type.
    """
    try:
        return node.get_input(port, type)
    except BTError as error:
        if port in getattr(node, "kinema_cell_ports", {}):
            # a port defaulting to the cell's value: the error says which config key to set
            raise PortValueError(error.message) from None
        raw = node.config.input_ports.get(port)
        key = node.port_blackboard_key(port)
        if raw is None:
            problem = "is not set"
        elif key is not None and getattr(node.config.blackboard.get_entry(key), "value", None) is None:
            problem = f"= {raw!r}, but nothing has written blackboard entry '{key}' yet"
        else:
            detail = error.message.split(": ", 1)[-1] if "can not be" in error.message else error.message
            problem = f"= {raw!r} cannot be read: {detail}"
        raise port_error(node, port, problem, _expected(node, port)) from None


def write_output(node: Any, port: str, value: Any) -> None:
    """``set_output`` whose failure (the entry holds another type) is a :class:`PortValueError`.

    Raises:
        PortValueError: naming the port, the value and the type the blackboard entry already holds.
    """
    try:
        node.set_output(port, value)
    except BTError as error:
        detail = error.message.split("once declared, the type of a port shall not change. ")[-1]
        raise port_error(node, port, f"cannot take {shown(value)}: {detail}", "") from None


def read_text(node: Any, port: str) -> str:
    """An optional text port: its value, or "" when it is not set.

    BT.CPP does not apply an empty default (``InputPort<std::string>(name, "", ...)``), so a port whose
    default is "" has no value unless the XML sets it; for optional text that means "".
    """
    if port not in node.config.input_ports:
        return ""
    return str(read_input(node, port))


def read_message(node: Any, port: str, ros_type: str | None = None) -> Any:
    """The message on input port ``port``, checked to be of ``ros_type`` (default: the port's type).

    Raises:
        PortValueError: missing value, or a value that is not such a message.
    """
    value = read_input(node, port, None if ros_type is None else message_type(ros_type))
    wanted = ros_type
    if wanted is None:
        manifest = node.config.manifest
        wanted = ros_type_of_port_type(manifest.ports[port].type) if manifest is not None else None
    if wanted is not None and getattr(value, "__msgtype__", None) != message_type(wanted).ros_type:
        raise port_error(node, port, f"got {shown(value)}", _expected(node, port) or f"expected a {wanted}")
    return value


def read_vector(node: Any, port: str) -> list[Any]:
    """The vector on input port ``port`` (a literal ``a;b;c`` becomes a list of strings).

    Raises:
        PortValueError: missing value or not a vector.
    """
    value = read_input(node, port)
    if isinstance(value, str):
        from kinema.bt.conversions import split_string

        return split_string(value)
    if not isinstance(value, list | tuple):
        raise port_error(node, port, f"got {shown(value)}", "expected a vector (e.g. from ResetVector)")
    return list(value)


def read_floats(node: Any, port: str, count: int, meaning: str) -> list[float]:
    """``count`` numbers from input port ``port`` (``"x;y;z"``), e.g. ``meaning="x;y;z"``.

    Raises:
        PortValueError: not numbers, or not exactly ``count`` of them.
    """
    values = read_input(node, port)
    try:
        numbers = [float(v) for v in (values if isinstance(values, list | tuple) else [values])]
    except (TypeError, ValueError):
        raise port_error(node, port, f"got {shown(values)}", f"expected {count} values {meaning}") from None
    if len(numbers) != count:
        raise port_error(
            node, port, f"has {len(numbers)} values {numbers}", f"expected {count} values {meaning}"
        )
    return numbers


def index_in(node: Any, port: str, index: int, vector: Sequence[Any], *, insert: bool = False) -> int:
    """``index`` checked against ``vector`` (negative indices are refused, as MoveIt Pro's are unsigned).

    Raises:
        PortValueError: the index is outside the vector, naming its valid range.
    """
    size = len(vector)
    upper = size if insert else size - 1
    if 0 <= index <= upper:
        return index
    if upper < 0:
        raise port_error(node, port, f"= {index} but the vector is empty", "no index is valid")
    raise port_error(node, port, f"= {index} is out of range", f"valid indices are 0..{upper}")


def fails_on_bad_input(method: F) -> F:
    """Wrap ``tick``/``on_start``/``do_work`` so a :class:`PortValueError` fails the node, not the tree.

    The error's message goes to ``publish_failure`` (a toast naming port, value and alternatives); the
    method then returns FAILURE (``False`` for ``do_work``).
    """
    failure: Any = False if method.__name__ == "do_work" else NodeStatus.FAILURE

    if inspect.iscoroutinefunction(method):

        @functools.wraps(method)
        async def async_wrapper(self: Any, *args: Any, **kwargs: Any) -> Any:
            try:
                return await method(self, *args, **kwargs)
            except PortValueError as error:
                self.logger.publish_failure(error.message)
                return failure

        return async_wrapper  # type: ignore[return-value]

    @functools.wraps(method)
    def wrapper(self: Any, *args: Any, **kwargs: Any) -> Any:
        try:
            return method(self, *args, **kwargs)
        except PortValueError as error:
            self.logger.publish_failure(error.message)
            return failure

    return wrapper  # type: ignore[return-value]
