"""CollisionObject and GraspableObject messages: unpack them into fields; build a GraspableObject."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from .ports import (
    NO_DEFAULT,
    fails_on_bad_input,
    message_input,
    message_output,
    message_vector_output,
    port_error,
    read_input,
    read_message,
    read_text,
    read_vector,
    shown,
)

COLLISION_OBJECT = "moveit_msgs/msg/CollisionObject"
GRASPABLE_OBJECT = "moveit_studio_vision_msgs/msg/GraspableObject"
POSE = "geometry_msgs/msg/Pose"

# (port, field, ROS element type or None for a plain value, is a vector, description)
_FIELDS: tuple[tuple[str, str, str | None, bool, str], ...] = (
    ("header", "header", "std_msgs/msg/Header", False, "Frame the poses are expressed in."),
    ("pose", "pose", POSE, False, "Pose of the object in the header's frame."),
    ("id", "id", None, False, "Name of the object in the planning scene."),
    ("type", "type", "object_recognition_msgs/msg/ObjectType", False, "Database key of the object type."),
    ("primitives", "primitives", "shape_msgs/msg/SolidPrimitive", True, "Solid primitives."),
    ("primitive_poses", "primitive_poses", POSE, True, "Pose of each primitive."),
    ("meshes", "meshes", "shape_msgs/msg/Mesh", True, "Meshes."),
    ("mesh_poses", "mesh_poses", POSE, True, "Pose of each mesh."),
    ("planes", "planes", "shape_msgs/msg/Plane", True, "Planes."),
    ("plane_poses", "plane_poses", POSE, True, "Pose of each plane."),
    ("subframe_names", "subframe_names", None, True, "Names of the object's subframes."),
    ("subframe_poses", "subframe_poses", POSE, True, "Pose of each subframe."),
    ("operation", "operation", None, False, "0 add, 1 remove, 2 append, 3 move."),
)


def _output(port: str, ros_type: str | None, vector: bool, description: str) -> PortInfo:
    default = "{" + port + "}"
    if ros_type is None:
        plain = list[str] if vector else (int if port == "operation" else str)
        return output_port(port, plain, default, description)
    if vector:
        return message_vector_output(port, ros_type, default, description)
    return message_output(port, ros_type, default, description)


def _input(port: str, ros_type: str | None, vector: bool, description: str) -> PortInfo:
    if ros_type is None:
        plain = list[str] if vector else (int if port == "operation" else str)
        return input_port(port, plain, 0 if port == "operation" else NO_DEFAULT, description)
    if vector:
        # Untyped, so a vector built by PushBackVector (a vector of any) connects; elements are checked
        # when read.
        return input_port(port, None, NO_DEFAULT, f"{description} (std::vector<{ros_type}>)")
    return message_input(port, ros_type, NO_DEFAULT, description)


def _field_value(node: Any, port: str, ros_type: str | None, vector: bool) -> Any:
    from kinema.transport.messages import to_dict

    if ros_type is None:
        value = read_input(node, port)
        if port == "operation":
            if int(value) not in (0, 1, 2, 3):
                raise port_error(node, port, f"= {value}", "valid: 0 add, 1 remove, 2 append, 3 move")
            return int(value)
        return [str(v) for v in value] if vector else str(value)
    if not vector:
        return to_dict(read_message(node, port))
    items = read_vector(node, port)
    wrong = [i for i, item in enumerate(items) if getattr(item, "__msgtype__", None) != ros_type]
    if wrong:
        raise port_error(
            node, port, f"element {wrong[0]} is {shown(items[wrong[0]])}", f"expected {ros_type}"
        )
    return [to_dict(item) for item in items]


SHAPES_AND_POSES = (
    ("primitives", "primitive_poses"),
    ("meshes", "mesh_poses"),
    ("planes", "plane_poses"),
    ("subframe_names", "subframe_poses"),
)


class CreateCollisionObjectMessage(SyncBehavior):
    """Builds a ``moveit_msgs/CollisionObject`` from the fields given (the others keep ROS defaults).

    Each list of shapes needs one pose per shape (``primitives``/``primitive_poses`` and so on).
    """

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            *(_input(port, ros_type, vector, text) for port, _, ros_type, vector, text in _FIELDS),
            message_output("collision_object", COLLISION_OBJECT, "{collision_object}", "The object."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.transport import from_dict

        given = self.config.input_ports
        data = {
            field: _field_value(self, port, ros_type, vector)
            for port, field, ros_type, vector, _ in _FIELDS
            if port in given
        }
        for shapes, poses in (
            ("primitives", "primitive_poses"),
            ("meshes", "mesh_poses"),
            ("planes", "plane_poses"),
            ("subframe_names", "subframe_poses"),
        ):
            if len(data.get(shapes, [])) != len(data.get(poses, [])):
                problem = f"has {len(data.get(poses, []))} poses for {len(data.get(shapes, []))} {shapes}"
                raise port_error(self, poses, problem, f"give one pose per element of {shapes}")
        self.set_output("collision_object", from_dict(COLLISION_OBJECT, data))
        return NodeStatus.SUCCESS


class UnpackCollisionObjectMessage(SyncBehavior):
    """Splits a ``moveit_msgs/CollisionObject`` into one output port per field."""

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "collision_object", COLLISION_OBJECT, "{collision_object}", "The object to unpack."
            ),
            *(_output(port, ros_type, vector, text) for port, _, ros_type, vector, text in _FIELDS),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        message = read_message(self, "collision_object")
        for port, field, _, vector, _ in _FIELDS:
            value = getattr(message, field)
            if port == "operation":
                value = int(value)
            elif vector:
                value = [str(v) for v in value] if port == "subframe_names" else list(value)
            self.set_output(port, value)
        return NodeStatus.SUCCESS


class CreateGraspableObjectMessage(SyncBehavior):
    """Builds a ``moveit_studio_vision_msgs/GraspableObject``: a collision object, a colour, grasp info."""

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("object", COLLISION_OBJECT, "{object}", "The object's collision geometry."),
            input_port("object_color", list[float], "0.5;0.5;0.5;1.0", "Display colour r;g;b;a (0..1)."),
            input_port("grasp_info", str, "", "Grasp information (free text)."),
            message_output(
                "graspable_object", GRASPABLE_OBJECT, "{graspable_object}", "The graspable object."
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema.transport import from_dict
        from kinema.transport.messages import to_dict

        from .ports import read_floats

        r, g, b, a = read_floats(self, "object_color", 4, "r;g;b;a")
        message = from_dict(
            GRASPABLE_OBJECT,
            {
                "object": to_dict(read_message(self, "object")),
                "object_color": {"r": r, "g": g, "b": b, "a": a},
                "grasp_info": read_text(self, "grasp_info"),
            },
        )
        self.set_output("graspable_object", message)
        return NodeStatus.SUCCESS


class UnpackGraspableObjectMessage(SyncBehavior):
    """Splits a ``moveit_studio_vision_msgs/GraspableObject`` into its three parts.

    MoveIt Pro does not publish this message's definition; Kinema's carries these three parts (the
    behavior's documented ports), with ``grasp_info`` as text.
    """

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "graspable_object", GRASPABLE_OBJECT, "{graspable_object}", "The object to unpack."
            ),
            message_output("object", COLLISION_OBJECT, "{object}", "Its collision geometry."),
            message_output("object_color", "std_msgs/msg/ColorRGBA", "{object_color}", "Its display colour."),
            output_port("grasp_info", str, "{grasp_info}", "Its grasp information."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        message = read_message(self, "graspable_object")
        self.set_output("object", message.object)
        self.set_output("object_color", message.object_color)
        self.set_output("grasp_info", str(message.grasp_info))
        return NodeStatus.SUCCESS
