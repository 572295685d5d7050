"""RegisterPointClouds: the rigid motion that lays one cloud onto another (ICP)."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

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

# The refinement pairs each target point closer than this (m) to the aligned base with the base.
REFINE_DISTANCE = 0.02


def refine_from_the_target(base: Any, target: Any, coarse: Any, iterations: int) -> Any:
    """Refine ``coarse`` (base onto target) by registering the target's points near the aligned base onto it.

    A CAD model (base) is complete while a camera sees only part of the object (target): pairing model
    points with the seen ones pulls the unseen faces onto seen ones, a bias of a centimetre or more. Every
    seen point, though, has its true partner on the model, so the reverse match is unbiased once the two
    are close. Returns ``coarse`` when too few target points are near the base to refine with.
    """
    import numpy as np
    from scipy.spatial import cKDTree

    from kinema.perception import register_icp

    moved = base.transformed(coarse.target_T_source)
    near, _ = cKDTree(moved.finite().points).query(
        target.finite().points, distance_upper_bound=REFINE_DISTANCE
    )
    close = target.finite().select(np.isfinite(near))
    if len(close) < 10:
        return coarse
    reverse = register_icp(
        close, moved, max_correspondence_distance=REFINE_DISTANCE, max_iterations=iterations
    )
    return replace(coarse, target_T_source=np.linalg.inv(reverse.target_T_source) @ coarse.target_T_source)


class RegisterPointClouds(AsyncBehavior):
    """Finds by point-to-point ICP the transform that moves ``base_point_cloud`` onto
    ``target_point_cloud`` and writes it as ``target_pose_in_base_frame`` (a pose in the target's frame).

    It is a correction on top of where the base cloud already is: a model cloud placed at a guess ``G``
    and registered gives ``T``; the object is at ``T * G`` (TransformPoseWithPose with input_pose ``G``,
    transform_pose ``T``). The base cloud is brought into the target's frame first. Fails when the clouds
    do not overlap within ``max_correspondence_distance`` or one has fewer than 3 points.

    Point-to-point ICP of the base onto the target comes first (what PCL does, MoveIt Pro's engine); it is
    then refined the other way round with the target points near the aligned base, which removes the
    pull of model faces the camera did not see.
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
            result = refine_from_the_target(base, target, result, iterations)
        except PerceptionError as error:
            self.logger.publish_failure(f"RegisterPointClouds: {error}")
            return False
        self.logger.publish_info(
            f"RegisterPointClouds: fitness {result.fitness:.2f}, RMSE {result.rmse * 1000:.1f} mm after "
            f"{result.iterations} iterations{'' if result.converged else ' (not converged)'}"
        )
        write_output(self, "target_pose_in_base_frame", pose_stamped_message(frame, result.target_T_source))
        return True
