"""MPCPointCloudClearance: MPC pose tracking that keeps the robot clear of a point cloud."""

from __future__ import annotations

from typing import TYPE_CHECKING

from kinema.behaviors import PortInfo

from ..messages.ports import message_input
from ..perception.clouds import POINT_CLOUD, frame_of, read_cloud, target_T_source
from .control_loop import MpcControlLoop, clearance_ports, common_ports

if TYPE_CHECKING:
    from kinema.motion.mpc import Obstacles


class MPCPointCloudClearance(MpcControlLoop):
    """Tracks ``target_pose`` as MPCPoseTracking does while keeping ``safe_distance`` from a point cloud.

    The cloud (``sensor_msgs/PointCloud2``, e.g. from GetPointCloud and CropPointsInBox) is placed in the
    world where its camera was when it was taken, and read again whenever the port's value changes.
    ``gripper_site_name`` and each frame of ``link_sites`` keep ``safe_distance`` from every point (the
    nearest points each step, through a k-d tree), a constraint of each step's QP: a target inside the
    clearance is approached only to its edge, and a frame that starts inside backs out. The rest (loop,
    controller, halting, ports) is as in MPCPoseTracking; defaults are the values lab_sim's objectives
    give (MoveIt Pro's own are not public).
    """

    clearance_weight_port = "point_cloud_clearance"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            *common_ports(horizon=0.1, site_tracking=0.45, warmup=256),
            message_input("point_cloud", POINT_CLOUD, "{point_cloud}", "The points to keep clear of."),
            *clearance_ports("point_cloud_clearance", 1.1, ""),
        ]

    def __init__(self, name: str, config: object = None) -> None:
        super().__init__(name, config)
        self._source: object = None
        self._obstacles: Obstacles | None = None

    def obstacles(self) -> Obstacles | None:
        message = self.get_input("point_cloud")
        if message is not self._source:
            self._obstacles = self._points()
            self._source = message
        return self._obstacles

    def _points(self) -> Obstacles:
        import numpy as np

        from kinema.motion.mpc import Obstacles

        cloud = read_cloud(self, "point_cloud")
        world_T_cloud = target_T_source(self, frame_of(cloud), "world", "point_cloud", at=cloud.stamp)
        points = np.asarray(cloud.points, dtype=float)
        points = points[np.isfinite(points).all(axis=1)]
        return Obstacles.from_points(points @ world_T_cloud[:3, :3].T + world_T_cloud[:3, 3])
