"""Motion: the robot model (pinocchio), kinematics, collision checking, OMPL planning, toppra timing, MPC.

Typical use::

    from kinema.motion import RobotDescription, CollisionChecker, plan_joint_goal, time_parameterize

    desc = RobotDescription.lab_sim()
    model = desc.load_model()
    checker = CollisionChecker(model, desc.load_scene(model), padding=0.01)
    path = plan_joint_goal(checker, q_start, {"shoulder_pan_joint": 0.5}, group="manipulator")
    trajectory = time_parameterize(path, model, velocity_scale=0.5)

Names are imported lazily, so ``import kinema.motion.trajectory`` does not load pinocchio or OMPL.
"""

from __future__ import annotations

from typing import Any

from kinema.lazy_exports import LazyExports

_EXPORTS = {
    "RobotModel": "robot_model",
    "JointGroup": "robot_model",
    "JointLimits": "joint_limits",
    "RobotDescription": "description",
    "fk": "kinematics",
    "frame_poses": "kinematics",
    "FrameTree": "frames",
    "CellFrames": "cell_frames",
    "JointStateMonitor": "joint_state_monitor",
    "ik": "inverse_kinematics",
    "ik_tips": "inverse_kinematics",
    "IkOptions": "inverse_kinematics",
    "PlanningScene": "planning_scene",
    "CollisionObject": "planning_scene",
    "AttachedObject": "planning_scene",
    "UrdfObject": "urdf_objects",
    "load_urdf_object": "urdf_objects",
    "CollisionChecker": "collision",
    "plan_joint_goal": "planner",
    "PlanningOptions": "planner",
    "PLANNERS": "planner",
    "plan_cartesian_path": "cartesian",
    "raster_poses": "coverage",
    "CartesianResult": "cartesian",
    "time_parameterize": "timing",
    "Task": "task",
    "TaskSolution": "task",
    "TaskPlanningError": "task",
    "plan_task": "task",
    "PoseTrackingMpc": "mpc",
    "MpcSettings": "mpc",
    "MpcPlan": "mpc",
    "Obstacles": "mpc",
    "JointPath": "trajectory",
    "JointTrajectory": "trajectory",
}
_lazy = LazyExports(__name__, _EXPORTS)

__all__ = _lazy.names


def __getattr__(name: str) -> Any:
    return _lazy.attribute(name)
