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
from .locations import file_to_read, file_to_write

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
    return [input_port("file_path", str, "", "YAML file; relative paths are in the objectives folder."), out]


def _save_ports(ros_type: str, what: str, overwrite: bool = True) -> list[PortInfo]:
    ports = [
        input_port("message", None, "{message}", f"{what} ({ros_type})."),
        input_port(
            "yaml_filename",
            str,
            "",
            "File to write ('.yaml' is added); relative names are in the objectives folder.",
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


class LoadPoseStampedFromYaml(AsyncBehavior):
    """Reads a ``geometry_msgs/PoseStamped`` from a YAML file into ``output``."""

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return _load_ports(POSE_STAMPED, False, "The pose.")

    @fails_on_bad_input
    def do_work(self) -> bool:
        path = file_to_read(self, "file_path", str(read_input(self, "file_path")))
        documents = read_documents(self, "file_path", path)
        if len(documents) != 1:
            problem = f"file {path} holds {len(documents)} documents"
            raise port_error(
                self, "file_path", problem, "use LoadPoseStampedVectorFromYaml for several poses"
            )
        self.set_output("output", message_from(self, "file_path", path, POSE_STAMPED, documents[0], 0))
        return True


class LoadPoseStampedVectorFromYaml(AsyncBehavior):
    """Reads a vector of ``geometry_msgs/PoseStamped`` (YAML documents split by ``---``) into ``output``."""

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return _load_ports(POSE_STAMPED, True, "The poses, in file order.")

    @fails_on_bad_input
    def do_work(self) -> bool:
        path = file_to_read(self, "file_path", str(read_input(self, "file_path")))
        documents = read_documents(self, "file_path", path)
        poses = [
            message_from(self, "file_path", path, POSE_STAMPED, doc, i + 1) for i, doc in enumerate(documents)
        ]
        self.set_output("output", poses)
        return True


class SavePoseStampedToYaml(AsyncBehavior):
    """Writes a ``geometry_msgs/PoseStamped`` to a YAML file, atomically."""

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return _save_ports(POSE_STAMPED, "The pose to save")

    @fails_on_bad_input
    def do_work(self) -> bool:
        message = read_message(self, "message", POSE_STAMPED)
        name = str(read_input(self, "yaml_filename"))
        save(self, "yaml_filename", name, [message], bool(read_input(self, "overwrite")))
        return True


class SavePoseStampedVectorToYaml(AsyncBehavior):
    """Writes a vector of ``geometry_msgs/PoseStamped`` to a YAML file (one document each), atomically."""

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return _save_ports(POSE_STAMPED, "The poses to save")

    @fails_on_bad_input
    def do_work(self) -> bool:
        poses = read_vector(self, "message")
        wrong = [i for i, pose in enumerate(poses) if getattr(pose, "__msgtype__", None) != POSE_STAMPED]
        if wrong:
            raise port_error(self, "message", f"element {wrong[0]} is not a {POSE_STAMPED}", "")
        name = str(read_input(self, "yaml_filename"))
        save(self, "yaml_filename", name, poses, bool(read_input(self, "overwrite")))
        return True


class LoadJointTrajectoryFromYaml(AsyncBehavior):
    """Reads a ``trajectory_msgs/JointTrajectory`` from a YAML file into ``output``."""

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return _load_ports(TRAJECTORY, False, "The trajectory.")

    @fails_on_bad_input
    def do_work(self) -> bool:
        path = file_to_read(self, "file_path", str(read_input(self, "file_path")))
        documents = read_documents(self, "file_path", path)
        if len(documents) != 1:
            raise port_error(self, "file_path", f"file {path} holds {len(documents)} documents", "expected 1")
        trajectory = message_from(self, "file_path", path, TRAJECTORY, documents[0], 0)
        if not len(trajectory.points):
            raise port_error(self, "file_path", f"file {path} has a trajectory without points", "")
        self.set_output("output", trajectory)
        return True


class SaveJointTrajectoryToYaml(AsyncBehavior):
    """Writes a ``trajectory_msgs/JointTrajectory`` to a YAML file, atomically."""

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return _save_ports(TRAJECTORY, "The trajectory to save")

    @fails_on_bad_input
    def do_work(self) -> bool:
        message = read_message(self, "message", TRAJECTORY)
        name = str(read_input(self, "yaml_filename"))
        save(self, "yaml_filename", name, [message], bool(read_input(self, "overwrite")))
        return True


class LoadRobotJointStateFromYaml(AsyncBehavior):
    """Reads a robot state (``RobotJointState``: joint state and multi-DOF state) from a YAML file."""

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("file_path", str, "", "YAML file; relative paths are in the objectives folder."),
            output_port("output", None, "{output}", f"The robot state ({ROBOT_STATE})."),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        path = file_to_read(self, "file_path", str(read_input(self, "file_path")))
        documents = read_documents(self, "file_path", path)
        if len(documents) != 1:
            raise port_error(self, "file_path", f"file {path} holds {len(documents)} documents", "expected 1")
        state = message_from(self, "file_path", path, ROBOT_STATE, documents[0], 0)
        if not len(state.joint_state.name):
            raise port_error(self, "file_path", f"file {path} names no joints", "expected joint_state.name")
        self.set_output("output", state)
        return True


class SaveRobotJointStateToYaml(AsyncBehavior):
    """Writes a robot state (or a joint state) to a YAML file as a ``RobotJointState``, atomically.

    An existing file is replaced (this behavior has no ``overwrite`` port in MoveIt Pro).
    """

    subcategory = SUBCATEGORY

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return _save_ports(ROBOT_STATE, "The robot or joint state to save", overwrite=False)

    @fails_on_bad_input
    def do_work(self) -> bool:
        state = as_robot_state(self, "message", read_input(self, "message"))
        save(self, "yaml_filename", str(read_input(self, "yaml_filename")), [state], True)
        return True
