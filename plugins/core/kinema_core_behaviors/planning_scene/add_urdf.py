"""AddURDF: a URDF (a tool, a part, a fixture) into the planning scene as one collision object."""

from __future__ import annotations

from kinema.behaviors import AsyncBehavior, PortInfo, input_port
from kinema.errors import KinemaError

from ..files.locations import file_to_read, split_package_uri
from ..messages.conversions import POSE_STAMPED_TYPE, pose_matrix
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    port_error,
    read_input,
    read_message,
    read_text,
)
from ..motion.planning_resources import robot_model
from ..poses.frame_tree import current_frame_tree


class AddURDF(AsyncBehavior):
    """Adds the collision geometry of a URDF to the planning scene as object ``urdf_name``, its root link at
    ``urdf_pose``.

    Every ``<collision>`` of the URDF's links counts (placed through its joints, movable joints at their
    zero position): boxes, cylinders and spheres exactly, a mesh as its bounding box. Later plans avoid
    it, ``kinema view`` draws it, AttachURDF binds it to the robot. An object of the same id is replaced
    (unless it is attached). As in MoveIt Pro the object is rigid: a tool's own joints are held, and a
    ``<ros2_control>`` block is not started (the behavior says so). Fails on a file it cannot find or
    read, a URDF without collision geometry, or a pose in a frame the cell does not know.
    """

    subcategory = "Motion - Planning Scene"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("urdf_name", str, "", "Id of the object in the planning scene."),
            input_port(
                "urdf_file_path",
                str,
                "",
                "The URDF (or xacro) file: inside package_name's folder when it is given (or a "
                "package://pkg/path URI), else relative to the objectives folder; absolute paths as written.",
            ),
            input_port(
                "package_name", str, "", "The package urdf_file_path is in ('' for the objectives folder)."
            ),
            message_input(
                "urdf_pose",
                POSE_STAMPED_TYPE,
                "{urdf_pose}",
                "Where the URDF's root link goes, in any frame.",
            ),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        from kinema.config.robot_description import package_index
        from kinema.motion.urdf_objects import load_urdf_object

        name = str(read_input(self, "urdf_name")).strip()
        if not name:
            raise port_error(self, "urdf_name", "is empty", "give the object an id, e.g. 'suction_gripper'")
        package, text = split_package_uri(str(read_input(self, "urdf_file_path")).strip())
        package = package or read_text(self, "package_name").strip()
        path = file_to_read(self, "urdf_file_path", text, package)
        frame, matrix = pose_matrix(read_message(self, "urdf_pose"), "urdf_pose")
        try:
            robot_model(self.context, "AddURDF")
            config = self.context.config
            urdf = load_urdf_object(path, package_index(config) if config is not None else None)
            world_T_root = (
                matrix
                if frame in ("", "world")
                else current_frame_tree(self).transform(matrix, frame, "world")
            )
            self.context.planning_scene.add_world_object(
                name, urdf.placed(world_T_root), replace=True, pose=world_T_root, urdf=True
            )
        except KinemaError as error:
            self.logger.publish_failure(f"AddURDF: {error}")
            return False
        held = []
        if urdf.held_joints:
            held.append(f"its joints {', '.join(urdf.held_joints)} are held at 0 (the object is rigid)")
        if urdf.ros2_control:
            held.append("its <ros2_control> block is not started")
        if held:
            self.logger.publish_info(f"AddURDF: {name!r} from {path.name}: " + "; ".join(held))
        return True
