"""Names → addresses in a MuJoCo model: joints, the actuator driving each joint, free bodies, keyframes.

Actuators are matched to joints by name, as MoveIt Pro's MujocoSystem does: an actuator named like a
joint commands that joint (directly, or through a tendon as lab_sim's gripper does) and the joint's
position is what it is measured by.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from kinema.errors import DriverError, did_you_mean


@dataclass(frozen=True)
class JointInfo:
    """A hinge or slide joint of the model.

    Attributes:
        name: the joint's name (MoveIt Pro's names in lab_sim).
        qpos_address: index into ``qpos``.
        dof_address: index into ``qvel`` / ``qfrc_*``.
        limits: position range (m or rad) when the joint is limited, else None.
        actuator: id of the actuator named like the joint, or None.
    """

    name: str
    qpos_address: int
    dof_address: int
    limits: tuple[float, float] | None
    actuator: int | None


@dataclass(frozen=True)
class JointCoupling:
    """A joint equality constraint ``q1 = c0 + c1·q2`` (lab_sim's gripper fingers follow the knuckle)."""

    joint1: str
    joint2: str
    offset: float
    factor: float


@dataclass(frozen=True)
class ModelIndex:
    """What the driver needs to find in a compiled ``mujoco.MjModel``.

    Attributes:
        joints: every hinge and slide joint, in model order (the ``/joint_states`` order).
        free_bodies: ``(name, body id)`` of every body with a free joint (the objects that can move).
        keyframes: keyframe names, in model order.
        couplings: linear joint equality constraints.
        timestep: the physics step, s.
    """

    joints: tuple[JointInfo, ...]
    free_bodies: tuple[tuple[str, int], ...]
    keyframes: tuple[str, ...]
    couplings: tuple[JointCoupling, ...]
    timestep: float

    @classmethod
    def from_model(cls, model: Any) -> ModelIndex:
        """Index ``model`` (a ``mujoco.MjModel``)."""
        import mujoco

        actuators = {model.actuator(i).name: i for i in range(model.nu) if model.actuator(i).name}
        joints = []
        free_bodies = []
        for j in range(model.njnt):
            kind = int(model.jnt_type[j])
            name = model.joint(j).name
            if kind == mujoco.mjtJoint.mjJNT_FREE:
                body = int(model.jnt_bodyid[j])
                free_bodies.append((model.body(body).name, body))
                continue
            if kind not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE) or not name:
                continue
            low, high = (float(x) for x in model.jnt_range[j])
            joints.append(
                JointInfo(
                    name=name,
                    qpos_address=int(model.jnt_qposadr[j]),
                    dof_address=int(model.jnt_dofadr[j]),
                    limits=(low, high) if model.jnt_limited[j] else None,
                    actuator=actuators.get(name),
                )
            )
        couplings = []
        for e in range(model.neq):
            if int(model.eq_type[e]) != mujoco.mjtEq.mjEQ_JOINT or int(model.eq_obj2id[e]) < 0:
                continue
            coefficients = model.eq_data[e]
            if np.any(np.abs(coefficients[2:5]) > 0.0):
                continue  # a nonlinear coupling: MuJoCo's solver settles it after a state change
            couplings.append(
                JointCoupling(
                    joint1=model.joint(int(model.eq_obj1id[e])).name,
                    joint2=model.joint(int(model.eq_obj2id[e])).name,
                    offset=float(coefficients[0]),
                    factor=float(coefficients[1]),
                )
            )
        keyframes = tuple(model.key(k).name for k in range(model.nkey))
        return cls(
            joints=tuple(joints),
            free_bodies=tuple(free_bodies),
            keyframes=keyframes,
            couplings=tuple(couplings),
            timestep=float(model.opt.timestep),
        )

    @property
    def joint_names(self) -> list[str]:
        """Names of :attr:`joints`, in order."""
        return [joint.name for joint in self.joints]

    @property
    def actuated_joints(self) -> list[JointInfo]:
        """The joints an actuator of the same name drives."""
        return [joint for joint in self.joints if joint.actuator is not None]

    def joint(self, name: str) -> JointInfo:
        """The joint called ``name``.

        Raises:
            DriverError: no such joint (the message lists the model's joints).
        """
        for joint in self.joints:
            if joint.name == name:
                return joint
        raise DriverError(f"the simulation has no joint {name!r}; {did_you_mean(name, self.joint_names)}")

    def keyframe_id(self, name: str) -> int:
        """The id of keyframe ``name``.

        Raises:
            DriverError: no such keyframe (the message lists the model's keyframes).
        """
        if name in self.keyframes:
            return self.keyframes.index(name)
        raise DriverError(f"the simulation has no keyframe {name!r}; {did_you_mean(name, self.keyframes)}")
