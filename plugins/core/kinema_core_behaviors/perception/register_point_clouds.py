"""RegisterPointClouds: the rigid motion that lays one cloud onto another (ICP)."""

from __future__ import annotations

from kinema.behaviors import AsyncBehavior, PortInfo, input_port
from kinema.errors import PerceptionError

from ..messages.conversions import POSE_STAMPED_TYPE, pose_stamped_message
from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    message_output,
    port_error,
    read_input,
    write_output,
)
from .clouds import POINT_CLOUD, frame_of, read_cloud, target_T_source


class RegisterPointClouds(AsyncBehavior):
    """Finds by point-to-point ICP the transform that moves ``base_point_cloud`` onto
    ``target_point_cloud`` and writes it as ``target_pose_in_base_frame`` (a pose in the target's frame).

    It is a correction on top of where the base cloud already is: a model cloud placed at a guess ``G``
    and registered gives ``T``; the object is at ``T * G`` (TransformPoseWithPose with input_pose ``G``,
    transform_pose ``T``). The base cloud is brought into the target's frame first. Fails when the clouds
    do not overlap within ``max_correspondence_distance`` or one has fewer than 3 points.
    """

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "base_point_cloud", POINT_CLOUD, "{base_point_cloud}", "The cloud to move (a model)."
            ),
            message_input(
                "target_point_cloud", POINT_CLOUD, "{target_point_cloud}", "The cloud to lay it onto."
            ),
            input_port(
                "max_correspondence_distance",
                float,
                0.5,
                "Points further apart (m) than this are not paired.",
            ),
            input_port("max_iterations", int, 30, "Most ICP iterations."),
            message_output(
                "target_pose_in_base_frame",
                POSE_STAMPED_TYPE,
                "{target_pose}",
                "The transform that moves the base cloud onto the target.",
            ),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        from kinema.perception import register_icp

        base = read_cloud(self, "base_point_cloud")
        target = read_cloud(self, "target_point_cloud")
        distance = float(read_input(self, "max_correspondence_distance"))
        if not distance > 0:
            raise port_error(self, "max_correspondence_distance", f"= {distance}", "give a length > 0 m")
        iterations = int(read_input(self, "max_iterations"))
        if iterations < 1:
            raise port_error(self, "max_iterations", f"= {iterations}", "give at least 1")
        frame = frame_of(target)
        base = base.transformed(target_T_source(self, frame_of(base), frame, "base_point_cloud"), frame)
        try:
            result = register_icp(
                base, target, max_correspondence_distance=distance, max_iterations=iterations
            )
        except PerceptionError as error:
            self.logger.publish_failure(f"RegisterPointClouds: {error}")
            return False
        self.logger.publish_info(
            f"RegisterPointClouds: fitness {result.fitness:.2f}, RMSE {result.rmse * 1000:.1f} mm after "
            f"{result.iterations} iterations{'' if result.converged else ' (not converged)'}"
        )
        write_output(self, "target_pose_in_base_frame", pose_stamped_message(frame, result.target_T_source))
        return True
