"""Messages as YAML files, in the layout MoveIt Pro writes them (``ros2 topic echo`` style).

Reading and writing run off the tick thread (the behaviors are asynchronous), so a large file never
holds the tree.

One message is one YAML document; a vector of messages is a stream of documents separated by ``---``
(as ``pill_bottle_place_poses.yaml``). Loading checks the fields against the message type, so a typo in
a field name or a wrong value fails with the file and the field named.
"""

from __future__ import annotations

import datetime
from pathlib import Path
from typing import Any

import yaml

from kinema.behaviors import AsyncBehavior, PortInfo, input_port, output_port
from kinema.config.atomic_write import atomic_write_bytes
from kinema.errors import KinemaError

from ..messages.ports import (
    fails_on_bad_input,
    message_output,
    message_vector_output,
    port_error,
    read_input,
    read_message,
    read_vector,
)
from ..messages.robot_state import as_robot_state
from .locations import RELATIVE_READ, RELATIVE_WRITE, file_to_read, file_to_write

POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
TRAJECTORY = "trajectory_msgs/msg/JointTrajectory"
ROBOT_STATE = "moveit_studio_agent_msgs/msg/RobotJointState"
SUBCATEGORY = "File Management"
# libyaml when PyYAML has it: a recorded trajectory is hundreds of kB, which the pure-Python parser takes
# seconds to read.
_LOADER: Any = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_DUMPER: Any = getattr(yaml, "CSafeDumper", yaml.SafeDumper)


def read_documents(node: Any, port: str, path: Path) -> list[Any]:
    """The YAML documents of ``path`` (empty documents dropped)."""
    try:
        text = path.read_text(encoding="utf-8")
        return [doc for doc in yaml.load_all(text, Loader=_LOADER) if doc is not None]
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark is not None else str(path)
        problem = getattr(error, "problem", None) or str(error)
        raise port_error(node, port, f"file {where} is not valid YAML: {problem}", "") from None
    except (OSError, UnicodeDecodeError) as error:
        raise port_error(node, port, f"file {path} cannot be read: {error}", "") from None


def message_from(node: Any, port: str, path: Path, ros_type: str, document: Any, number: int) -> Any:
    """Document ``number`` of ``path`` as a ``ros_type`` message."""
    from kinema.transport import from_dict

    where = f"{path} (document {number})" if number else str(path)
    if not isinstance(document, dict):
        raise port_error(
            node, port, f"file {where} holds {type(document).__name__}", f"expected a {ros_type} mapping"
        )
    try:
        return from_dict(ros_type, document)
    except KinemaError as error:
        raise port_error(node, port, f"file {where} is not a {ros_type}: {error.message}", "") from None


def dump(messages: list[Any]) -> bytes:
    """YAML text of one message or a document stream of several."""
    from kinema.transport.messages import to_dict

    return yaml.dump_all(
        [to_dict(message) for message in messages], Dumper=_DUMPER, sort_keys=False, default_flow_style=False
    ).encode()


def save(node: Any, port: str, text: str, messages: list[Any], overwrite: bool) -> Path:
    """Write ``messages`` to the file ``text`` names, atomically (an old file stays unless ``overwrite``)."""
    path = file_to_write(node, port, text, ".yaml")
    if path.exists() and not overwrite:
        stamp = datetime.datetime.now().strftime("%Y%m%d_%H%M%S")
        kept = path
        path = path.with_name(f"{path.stem}_{stamp}{path.suffix}")
        node.logger.publish_info(f"{kept} exists and overwrite is false: saving to {path.name}")
    try:
        atomic_write_bytes(path, dump(messages))
    except KinemaError as error:
        raise port_error(node, port, f"= {text!r}: {error}", "") from None
    return path


def _load_ports(ros_type: str, vector: bool, what: str) -> list[PortInfo]:
    out = (message_vector_output if vector else message_output)("output", ros_type, "{output}", what)
    return [input_port("file_path", str, "", f"YAML file; {RELATIVE_READ}."), out]


def _save_ports(ros_type: str, what: str, overwrite: bool = True) -> list[PortInfo]:
    ports = [
        input_port("message", None, "{message}", f"{what} ({ros_type})."),
        input_port(
            "yaml_filename",
            str,
            "",
            f"File to write ('.yaml' is added); {RELATIVE_WRITE}.",
        ),
    ]
    if overwrite:
        ports.append(
            input_port(
                "overwrite",
                bool,
                True,
                "Replace an existing file. When false and the file exists, the message is saved beside it "
                "with a time stamp in the name. (MoveIt Pro's default is not public; the corpus implies "
                "true: 'Record and Replay Scanning Motion' replays the joint_trajectory.yaml that 'Plan and "
                "Save Trajectory' saves over the shipped one without setting overwrite.)",
            )
        )
    return ports


class _LoadFromYaml(AsyncBehavior):
    """Reads ``ros_type`` messages from a YAML file into ``output``: the shape every loader shares.

    Subclasses set the message type, whether the file holds one message or a vector, what the output
    is, and may check the loaded message (:meth:`check`).
    """

    subcategory = SUBCATEGORY
    ros_type = ""
    vector = False
    what = ""
    several_hint = "expected 1"  # the valid alternative when a one-message file holds several documents

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return _load_ports(cls.ros_type, cls.vector, cls.what)

    def check(self, message: Any, path: Path) -> None:
        """Raise :func:`port_error` when the loaded ``message`` is unusable (nothing to check by default)."""

    @fails_on_bad_input
    def do_work(self) -> bool:
        path = file_to_read(self, "file_path", str(read_input(self, "file_path")))
        documents = read_documents(self, "file_path", path)
        if self.vector:
            messages = [
                message_from(self, "file_path", path, self.ros_type, doc, i + 1)
                for i, doc in enumerate(documents)
            ]
            self.set_output("output", messages)
            return True
        if len(documents) != 1:
            raise port_error(
                self, "file_path", f"file {path} holds {len(documents)} documents", self.several_hint
            )
        message = message_from(self, "file_path", path, self.ros_type, documents[0], 0)
        self.check(message, path)
        self.set_output("output", message)
        return True


class _SaveToYaml(AsyncBehavior):
    """Writes the ``message`` input (a ``ros_type``) to a YAML file, atomically: the shape every saver
    shares. Subclasses set the type and what is saved, and may convert the input (:meth:`messages`)."""

    subcategory = SUBCATEGORY
    ros_type = ""
    what = ""
    has_overwrite = True

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return _save_ports(cls.ros_type, cls.what, overwrite=cls.has_overwrite)

    def messages(self) -> list[Any]:
        """The messages to write (one document each)."""
        return [read_message(self, "message", self.ros_type)]

    @fails_on_bad_input
    def do_work(self) -> bool:
        messages = self.messages()
        overwrite = bool(read_input(self, "overwrite")) if self.has_overwrite else True
        save(self, "yaml_filename", str(read_input(self, "yaml_filename")), messages, overwrite)
        return True


class LoadPoseStampedFromYaml(_LoadFromYaml):
    """Reads a ``geometry_msgs/PoseStamped`` from a YAML file into ``output``."""

    ros_type = POSE_STAMPED
    what = "The pose."
    several_hint = "use LoadPoseStampedVectorFromYaml for several poses"


class LoadPoseStampedVectorFromYaml(_LoadFromYaml):
    """Reads a vector of ``geometry_msgs/PoseStamped`` (YAML documents split by ``---``) into ``output``."""

    ros_type = POSE_STAMPED
    vector = True
    what = "The poses, in file order."


class SavePoseStampedToYaml(_SaveToYaml):
    """Writes a ``geometry_msgs/PoseStamped`` to a YAML file, atomically.

    With a ``namespace`` the pose is written under that top-level key, and the file's other keys stay: one
    file collects a pose per run (``namespace="{run_counter}"``). An existing key is replaced when
    ``overwrite`` is true; otherwise the file is saved beside with a time stamp, as a file is.
    """

    ros_type = POSE_STAMPED
    what = "The pose to save"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            *super().provided_ports(),
            input_port(
                "namespace",
                None,
                "",
                "Top-level key the pose is saved under, beside the file's other keys ('': the file is the "
                "pose). MoveIt Pro's layout is not public; this is Kinema's.",
            ),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        namespace = (
            str(read_input(self, "namespace")).strip() if "namespace" in self.config.input_ports else ""
        )
        if not namespace:
            return bool(super().do_work())
        from kinema.transport.messages import to_dict

        message = read_message(self, "message", POSE_STAMPED)
        text = str(read_input(self, "yaml_filename"))
        overwrite = bool(read_input(self, "overwrite"))
        path = file_to_write(self, "yaml_filename", text, ".yaml")
        entries: dict[str, Any] = {}
        if path.exists():
            documents = read_documents(self, "yaml_filename", path)
            held = documents[0] if len(documents) == 1 and isinstance(documents[0], dict) else None
            if held is not None:
                entries = {str(key): value for key, value in held.items()}
            if (held is None or namespace in entries) and not overwrite:
                stamp = datetime.datetime.now().strftime("%Y%m%d_%H%M%S")
                kept, path = path, path.with_name(f"{path.stem}_{stamp}{path.suffix}")
                what = f"holds {namespace!r}" if held is not None else "is not a file of namespaces"
                self.logger.publish_info(f"{kept} {what} and overwrite is false: saving to {path.name}")
                entries = {}
            elif held is None:
                entries = {}
        entries[namespace] = to_dict(message)
        data = yaml.dump(entries, Dumper=_DUMPER, sort_keys=False, default_flow_style=False).encode()
        try:
            atomic_write_bytes(path, data)
        except KinemaError as error:
            raise port_error(self, "yaml_filename", f"= {text!r}: {error}", "") from None
        return True


class SavePoseStampedVectorToYaml(_SaveToYaml):
    """Writes a vector of ``geometry_msgs/PoseStamped`` to a YAML file (one document each), atomically."""

    ros_type = POSE_STAMPED
    what = "The poses to save"

    def messages(self) -> list[Any]:
        poses = read_vector(self, "message")
        wrong = [i for i, pose in enumerate(poses) if getattr(pose, "__msgtype__", None) != POSE_STAMPED]
        if wrong:
            raise port_error(self, "message", f"element {wrong[0]} is not a {POSE_STAMPED}", "")
        return list(poses)


class LoadJointTrajectoryFromYaml(_LoadFromYaml):
    """Reads a ``trajectory_msgs/JointTrajectory`` from a YAML file into ``output``."""

    ros_type = TRAJECTORY
    what = "The trajectory."

    def check(self, message: Any, path: Path) -> None:
        if not len(message.points):
            raise port_error(self, "file_path", f"file {path} has a trajectory without points", "")


class SaveJointTrajectoryToYaml(_SaveToYaml):
    """Writes a ``trajectory_msgs/JointTrajectory`` to a YAML file, atomically."""

    ros_type = TRAJECTORY
    what = "The trajectory to save"


class LoadRobotJointStateFromYaml(_LoadFromYaml):
    """Reads a robot state (``RobotJointState``: joint state and multi-DOF state) from a YAML file."""

    ros_type = ROBOT_STATE

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("file_path", str, "", f"YAML file; {RELATIVE_READ}."),
            output_port("output", None, "{output}", f"The robot state ({ROBOT_STATE})."),
        ]

    def check(self, message: Any, path: Path) -> None:
        if not len(message.joint_state.name):
            raise port_error(self, "file_path", f"file {path} names no joints", "expected joint_state.name")


class SaveRobotJointStateToYaml(_SaveToYaml):
    """Writes a robot state (or a joint state) to a YAML file as a ``RobotJointState``, atomically.

    An existing file is replaced (this behavior has no ``overwrite`` port in MoveIt Pro).
    """

    ros_type = ROBOT_STATE
    what = "The robot or joint state to save"
    has_overwrite = False

    def messages(self) -> list[Any]:
        return [as_robot_state(self, "message", read_input(self, "message"))]
