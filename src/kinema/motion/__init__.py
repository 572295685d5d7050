"""Motion: the robot model (pinocchio), kinematics, collision checking, OMPL planning and toppra timing.

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

import importlib
from typing import Any

_EXPORTS = {
    "RobotModel": "robot_model",
    "JointGroup": "robot_model",
    "JointLimits": "joint_limits",
    "RobotDescription": "description",
    "fk": "kinematics",
    "frame_poses": "kinematics",
    "FrameTree": "frames",
    "ik": "inverse_kinematics",
    "IkOptions": "inverse_kinematics",
    "PlanningScene": "planning_scene",
    "CollisionObject": "planning_scene",
    "CollisionChecker": "collision",
    "plan_joint_goal": "planner",
    "PlanningOptions": "planner",
    "PLANNERS": "planner",
    "plan_cartesian_path": "cartesian",
    "CartesianResult": "cartesian",
    "time_parameterize": "timing",
    "Task": "task",
    "TaskSolution": "task",
    "TaskPlanningError": "task",
    "plan_task": "task",
    "JointPath": "trajectory",
    "JointTrajectory": "trajectory",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'kinema.motion' has no attribute {name!r}")
    return getattr(importlib.import_module(f"kinema.motion.{module}"), name)
