"""GetGraspableObjectsFromMasks3D and ExtractGraspableObjectPose: each masked object of a cloud as a
box-shaped GraspableObject, and the pose a grasp or a push goes to.

The objects are ``moveit_studio_vision_msgs/GraspableObject`` messages (a CollisionObject, a colour, grasp
info) as Kinema defines them: UnpackGraspableObjectMessage → AddCollisionObject puts one in the planning
scene, ExtractGraspableObjectPose gives its pose to SetupMTCPlanToPose. FindMaskedObjects builds its
objects here too.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, output_port

from ..messages.conversions import POSE_STAMPED_TYPE, pose_stamped_message
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    message_output,
    port_error,
    read_input,
    read_message,
    read_vector,
    write_output,
)
from .clouds import POINT_CLOUD, frame_of, read_cloud, target_T_source
from .masks import MASK3D, mask3d_indices

GRASPABLE_OBJECT = "moveit_studio_vision_msgs/msg/GraspableObject"
# How the perception behaviors' objects show in the UI.
OBJECT_COLOR = {"r": 0.2, "g": 0.6, "b": 0.9, "a": 1.0}


def graspable_box(frame: str, name: str, pose: np.ndarray, size: np.ndarray) -> Any:
    """A GraspableObject holding one box of full ``size`` (3, m) at ``pose`` (4x4, in ``frame``).

    The box's pose is the CollisionObject's ``pose`` (its one primitive sits at the identity within it), so
    ExtractGraspableObjectPose and the planning scene read the same place.
    """
    from kinema import transforms
    from kinema.motion.planning_scene_messages import collision_object_message, shape_constants
    from kinema.transport import from_dict

    return from_dict(
        GRASPABLE_OBJECT,
        {
            "object": {
                "header": {"frame_id": frame},
                "id": name,
                "pose": transforms.pose_dict(pose),
                "primitives": [{"type": shape_constants().BOX, "dimensions": [float(v) for v in size]}],
                "primitive_poses": [{"orientation": {"w": 1.0}}],
                "operation": collision_object_message().ADD,
            },
            "object_color": OBJECT_COLOR,
            "grasp_info": "",
        },
    )


class GetGraspableObjectsFromMasks3D(SyncBehavior):
    """For each Mask3D of ``masks3d``, the object its points of ``point_cloud`` show, in ``base_frame``, as a
    GraspableObject holding one box (id ``object_<mask index>``).

    The box is fitted to the face the camera sees (the origin of the cloud's frame is taken as the
    camera): the face is the plane most of the mask's points lie on, within ``plane_inlier_threshold``;
    points more than ``face_separation_threshold`` behind it (the wall seen past a handle) or more than
    ``plane_inlier_threshold`` in front of it (stray depth) are not the object's. The box's z axis is the
    face's normal pointing away from the camera, into the object, so ExtractGraspableObjectPose gives a
    pose a tool can approach along its z (Push Button ML pushes along it); x is the face's longest side, y
    completes the frame. The box reaches from the face to the deepest point kept, at least
    ``plane_inlier_threshold`` thick: a camera sees an object's front, not its back.

    A mask with fewer than 3 points, points on a line, or a face smaller than ``minimum_face_area`` gives
    no object (said in the log); so the output may be empty, as MoveIt Pro's is when nothing fits. Fails
    when a mask lists points the cloud does not have.
    """

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("point_cloud", POINT_CLOUD, "{point_cloud}", "The cloud the masks were made from."),
            input_port("masks3d", None, "{masks3d}", "The objects' point indices (std::vector<Mask3D>)."),
            input_port("base_frame", str, "world", "The frame the objects are expressed in."),
            input_port(
                "plane_inlier_threshold",
                float,
                0.01,
                "How far (m) from the face's plane a point is still on the face; the box's least thickness.",
            ),
            input_port(
                "minimum_face_area",
                float,
                0.000625,
                "Smallest visible face (m², its length times its width) an object is made of.",
            ),
            input_port(
                "face_separation_threshold",
                float,
                0.02,
                "How far (m) behind the face a point may lie and still be the object's.",
            ),
            output_port(
                "graspable_objects",
                None,
                "{graspable_objects}",
                "One box per mask that fits (std::vector<GraspableObject>), in mask order.",
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        from kinema.errors import PerceptionError
        from kinema.perception import fit_face_box

        cloud = read_cloud(self, "point_cloud")
        base = str(read_input(self, "base_frame"))
        inlier = self._distance("plane_inlier_threshold")
        separation = self._distance("face_separation_threshold")
        minimum_area = self._distance("minimum_face_area")
        base_T_cloud = target_T_source(self, frame_of(cloud), base, "base_frame")
        camera = base_T_cloud[:3, 3]
        points = cloud.transformed(base_T_cloud, base).points.astype(float)
        objects: list[Any] = []
        skipped: list[str] = []
        for index, mask in enumerate(read_vector(self, "masks3d")):
            if getattr(mask, "__msgtype__", None) != MASK3D:
                raise port_error(
                    self,
                    "masks3d",
                    f"element {index} is not a {MASK3D}",
                    "give GetMasks3DFromMasks2D's masks3d",
                )
            chosen = points[mask3d_indices(self, "masks3d", mask, len(points))]
            try:
                box = fit_face_box(chosen, camera, inlier, separation)
            except PerceptionError as error:
                skipped.append(f"mask {index}: {error}")
                continue
            if box.face_area < minimum_area:
                skipped.append(f"mask {index}: face of {box.face_area:.6f} m² < minimum_face_area")
                continue
            objects.append(graspable_box(base, f"object_{index}", box.pose, np.asarray(box.size)))
        if skipped:
            self.logger.publish_info(f"{self.registration_id}: no object for " + "; ".join(skipped))
        write_output(self, "graspable_objects", objects)
        return NodeStatus.SUCCESS

    def _distance(self, port: str) -> float:
        value = float(read_input(self, port))
        if not value >= 0.0:
            raise port_error(self, port, f"= {value}", "give a value of 0 or more")
        return value


class ExtractGraspableObjectPose(SyncBehavior):
    """Writes the pose of ``graspable_object``, in its header's frame: the CollisionObject's ``pose``
    followed by its first primitive's pose (so where its box is, whether the object places the box by its
    own pose, as GetGraspableObjectsFromMasks3D does, or by the primitive's, as a hand-built object may).
    An object without primitives gives its own pose. For GetGraspableObjectsFromMasks3D's objects that is
    the box's centre with z into the object, away from the camera."""

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "graspable_object",
                GRASPABLE_OBJECT,
                "{graspable_object}",
                "The object, e.g. a ForEach element.",
            ),
            message_output("pose", POSE_STAMPED_TYPE, "{pose}", "Its pose, in its header's frame."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        from kinema import transforms

        target = read_message(self, "graspable_object", GRASPABLE_OBJECT).object
        try:
            pose = transforms.pose_from_message(target.pose)
            if len(target.primitive_poses):
                pose = pose @ transforms.pose_from_message(target.primitive_poses[0])
        except transforms.TransformError as error:
            raise port_error(self, "graspable_object", str(error), "") from None
        write_output(self, "pose", pose_stamped_message(str(target.header.frame_id), pose))
        return NodeStatus.SUCCESS
