"""MPC: track a moving target pose by model predictive control, clear of spheres or a point cloud.

MoveIt Pro's MPCBehaviorsLoader behaviors (its alias ``moveit_pro::behaviors::MPCBehaviorsLoader`` loads
the core plugin). The optimiser is :mod:`kinema.motion.mpc`; the loop they share is :mod:`.control_loop`.
"""

from __future__ import annotations

from .mpc_point_cloud_clearance import MPCPointCloudClearance
from .mpc_pose_tracking import MPCPoseTracking
from .mpc_sphere_clearance import MPCSphereClearance

BEHAVIORS = (MPCPoseTracking, MPCSphereClearance, MPCPointCloudClearance)
