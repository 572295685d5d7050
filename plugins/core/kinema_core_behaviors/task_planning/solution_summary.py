"""What a planned solution does, for a person about to approve it, and drawing it in ``kinema view``.

WaitForMTCSolutionApproval sends :func:`solution_steps` with its question (the TUI lists them) and calls
:func:`show_solution` so the view draws the motion while the question is open. A solution is an MTC
solution (PlanMTCTask) or a ``trajectory_msgs/JointTrajectory`` (PlanCartesianPath's debug solution).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ..messages.conversions import trajectory_message
from ..motion.planned_trajectory import publish_planned_trajectory

JOINT_TRAJECTORY = "trajectory_msgs/msg/JointTrajectory"
MOVED = 1e-4  # rad or m: a gripper joint that changes less holds still


def solution_steps(solution: Any, model: Any = None) -> tuple[list[dict[str, Any]], float]:
    """The motions of ``solution`` (``kinema_msgs/SolutionStep`` fields) and its whole duration, seconds.

    An MTC solution's collision-rule changes come in their place between the motions, as steps with a
    ``note``, no joints and no duration.

    ``model`` (the robot model) names the gripper joints (its SRDF end effectors' joints); without it no
    gripper change is reported. Anything else than a solution or a trajectory has no steps.
    """
    from kinema.motion.task import TaskSolution

    if isinstance(solution, TaskSolution):
        grippers = _gripper_joints(model)
        steps: list[dict[str, Any]] = []
        for k, sub in enumerate([*solution.sub_trajectories, None]):
            steps += [
                {
                    "stage": change.stage,
                    "duration": 0.0,
                    "joint_names": [],
                    "gripper": "",
                    "note": change.description,
                }
                for change in solution.scene_changes
                if change.before == k
            ]
            if sub is None:
                continue
            trajectory = sub.trajectory
            gripper = _gripper_change(
                trajectory.joint_names, trajectory.positions[0], trajectory.positions[-1], grippers, model
            )
            steps.append(
                {
                    "stage": sub.stage,
                    "duration": float(trajectory.duration),
                    "joint_names": list(trajectory.joint_names),
                    "gripper": gripper,
                    "note": "",
                }
            )
        return steps, float(sum(step["duration"] for step in steps))
    if getattr(solution, "__msgtype__", None) == JOINT_TRAJECTORY and solution.points:
        last = solution.points[-1].time_from_start
        duration = float(last.sec) + float(last.nanosec) * 1e-9
        names = [str(n) for n in solution.joint_names]
        gripper = _gripper_change(
            names,
            list(solution.points[0].positions),
            list(solution.points[-1].positions),
            _gripper_joints(model),
            model,
        )
        return [
            {"stage": "trajectory", "duration": duration, "joint_names": names, "gripper": gripper}
        ], duration
    return [], 0.0


def show_solution(behavior: Any, solution: Any, model: Any = None, links: Sequence[str] = ()) -> None:
    """Draw ``solution`` in ``kinema view``: its motion, and the path of each of ``links`` along it (for an
    MTC solution stage by stage; without ``links``, the tool's path of each stage of an MTC solution)."""
    from kinema.motion.task import TaskSolution

    if isinstance(solution, TaskSolution):
        from .plan_task import publish_stage_paths

        publish_planned_trajectory(behavior, trajectory_message(solution.joined()))
        if model is not None:
            publish_stage_paths(behavior, solution, model, links)
    elif getattr(solution, "__msgtype__", None) == JOINT_TRAJECTORY:
        publish_planned_trajectory(behavior, solution)
        if model is not None and links and solution.points:
            from .plan_task import publish_paths

            publish_paths(behavior, [(link, trajectory_link_path(model, solution, link)) for link in links])


def trajectory_link_path(model: Any, message: Any, link: str, start: Any = None) -> Any:
    """Where ``link`` goes along a ``trajectory_msgs/JointTrajectory``: positions ``(N, 3)`` in the world.

    Joints the trajectory does not move stay at ``start`` (a configuration over the model's joints; the
    model's zero configuration by default).
    """
    import numpy as np

    from kinema.motion import fk

    q = np.zeros(len(model.joint_names)) if start is None else np.array(start, dtype=float)
    index = {name: i for i, name in enumerate(model.joint_names)}
    columns = [(k, index[str(n)]) for k, n in enumerate(message.joint_names) if str(n) in index]
    data = model.new_data()
    points = []
    for point in message.points:
        for k, i in columns:
            q[i] = float(point.positions[k])
        points.append(fk(model, q, link, data)[:3, 3])
    return np.array(points)


def _gripper_joints(model: Any) -> dict[str, str]:
    """Gripper joint -> its end-effector group."""
    if model is None:
        return {}
    joints: dict[str, str] = {}
    for effector in model.semantic.end_effectors:
        if effector.group in model.groups:
            for name in model.group(effector.group).joint_names:
                joints[name] = effector.group
    return joints


def _gripper_change(names: Any, first: Any, last: Any, grippers: dict[str, str], model: Any) -> str:
    changes = []
    for name, a, b in zip(names, first, last, strict=True):
        if name not in grippers or abs(float(b) - float(a)) <= MOVED:
            continue
        text = f"{name} {float(a):.3f} -> {float(b):.3f}"
        direction = _direction(model, grippers[name], name, float(a), float(b))
        changes.append(f"{text} ({direction})" if direction else text)
    return "; ".join(changes)


def _direction(model: Any, group: str, joint: str, start: float, end: float) -> str:
    """``closes`` or ``opens`` when the SRDF names the group's open and close states."""
    states = model.semantic.group_states
    opened, closed = states.get((group, "open"), {}), states.get((group, "close"), {})
    if joint not in opened or joint not in closed:
        return ""
    toward_closed = abs(end - closed[joint]) < abs(start - closed[joint])
    return "closes" if toward_closed else "opens"
