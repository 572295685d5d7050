"""Read and set the simulated scene: free body poses, joint positions, keyframes.

Every function here takes the model and data and must run on the physics thread.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from kinema.drivers.mujoco.model_index import ModelIndex
from kinema.errors import DriverError


@dataclass(frozen=True)
class BodyPose:
    """A body's pose in the world frame: ``position`` (m) and ``orientation`` as a quaternion x, y, z, w."""

    name: str
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]


def free_body_poses(data: Any, index: ModelIndex) -> list[BodyPose]:
    """World poses of the free bodies (as of the last ``mj_step``/``mj_forward``)."""
    poses = []
    for name, body in index.free_bodies:
        x, y, z = (float(v) for v in data.xpos[body])
        w, qx, qy, qz = (float(v) for v in data.xquat[body])  # MuJoCo stores w first
        poses.append(BodyPose(name, (x, y, z), (qx, qy, qz, w)))
    return poses


def reset_to_keyframe(model: Any, data: Any, index: ModelIndex, name: str) -> None:
    """Reset the whole scene to keyframe ``name``, keeping sim time running forward.

    Raises:
        DriverError: no such keyframe.
    """
    import mujoco

    key = index.keyframe_id(name)
    now = data.time
    mujoco.mj_resetDataKeyframe(model, data, key)
    # /clock must never run backwards: subscribers' timers are keyed to it.
    data.time = now
    mujoco.mj_forward(model, data)


def check_joint_positions(index: ModelIndex, positions: Mapping[str, float]) -> None:
    """Check that every name is a joint of the model and every position is within the joint's limits.

    Raises:
        DriverError: an unknown joint (the message lists the model's joints) or a position out of range.
    """
    for name, value in positions.items():
        joint = index.joint(name)
        if not math.isfinite(value):
            raise DriverError(f"{name} = {value} is not a finite position")
        if joint.limits is not None and not joint.limits[0] - 1e-6 <= value <= joint.limits[1] + 1e-6:
            raise DriverError(
                f"{name} = {value:.6g} is outside its limits [{joint.limits[0]:.6g}, {joint.limits[1]:.6g}]"
            )


def apply_joint_state(
    model: Any,
    data: Any,
    index: ModelIndex,
    positions: Mapping[str, float],
    velocities: Mapping[str, float] | None = None,
) -> list[str]:
    """Set joint positions (and velocities, default zero) and command the joints' actuators to hold there.

    Joints coupled to a set joint by a linear equality constraint (lab_sim's fingers follow the
    knuckle) are moved with it, so the constraint does not snap them back.

    Returns:
        The names of every joint that was set, coupled ones included.

    Raises:
        DriverError: an unknown joint name (the message lists the model's joints), or a position
            outside a joint's limits.
    """
    import mujoco

    check_joint_positions(index, positions)
    targets = {name: float(value) for name, value in positions.items()}
    changed = True
    while changed:
        changed = False
        for coupling in index.couplings:
            if coupling.joint1 in targets and coupling.joint2 not in targets and coupling.factor != 0.0:
                targets[coupling.joint2] = (targets[coupling.joint1] - coupling.offset) / coupling.factor
                changed = True
            elif coupling.joint2 in targets and coupling.joint1 not in targets:
                targets[coupling.joint1] = coupling.offset + coupling.factor * targets[coupling.joint2]
                changed = True
    speeds = dict(velocities or {})
    for name, value in targets.items():
        joint = index.joint(name)
        data.qpos[joint.qpos_address] = value
        data.qvel[joint.dof_address] = float(speeds.get(name, 0.0))
        if joint.actuator is not None:
            data.ctrl[joint.actuator] = value
    mujoco.mj_forward(model, data)
    return list(targets)
