"""Admittance: a trajectory that gives way to the wrench the wrist measures, as a mass-spring-damper.

The joint trajectory admittance controller tracks a joint trajectory and, per goal, lets the control frame
(lab_sim: ``grasp_site`` at ``grasp_link``) deviate from where the trajectory puts it. On each selected axis
of the control frame the offset ``x`` (m, or rad about the axis) follows

    M a + D v + K x = F,   D = 2 ζ sqrt(M K)

with ``F`` the external wrench at the control frame: the sensor's reading minus the tool's own weight
(from the model's masses below the sensor, so a tool tilted by the admittance does not push itself) minus
the reading the sensor was zeroed at. It is integrated implicitly (backward Euler), which is stable for
any mass, damping and stiffness at the physics step. The offset's velocity becomes joint velocities by
damped least squares on MuJoCo's Jacobian of the control frame, integrated into a joint offset that the
controller adds to the trajectory's set points; the part of that joint offset the Cartesian offset does
not need (the null space of a redundant arm) decays at ``joint_damping`` (1/s). Axes not selected stay
rigid: no offset along them.

All methods run on the physics thread.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

AXES = ("x", "y", "z", "rx", "ry", "rz")


class AdmittanceError(ValueError):
    """Admittance parameters the controller cannot use; the message names the value."""


@dataclass(frozen=True)
class AdmittanceParameters:
    """The compliance of one goal, as plain arrays (6 per Cartesian axis: x, y, z, rx, ry, rz).

    Attributes:
        selected: the compliant axes.
        mass: kg (linear axes) and kg m^2 (rotational).
        stiffness: N/m and N m/rad.
        damping_ratio: fractions of critical damping.
        joint_damping: 1/s, the decay of the joint offset in the arm's null space.
        control_frame: the MuJoCo site or body the admittance acts in ("": the controller's own).
    """

    selected: np.ndarray
    mass: np.ndarray
    stiffness: np.ndarray
    damping_ratio: np.ndarray
    joint_damping: float = 0.0
    control_frame: str = ""

    @property
    def damping(self) -> np.ndarray:
        """N s/m and N m s/rad: ``2 ζ sqrt(M K)`` (ros2_controllers' admittance convention)."""
        return 2.0 * self.damping_ratio * np.sqrt(self.mass * self.stiffness)

    @classmethod
    def from_message(cls, message: Any) -> AdmittanceParameters | None:
        """Read a ``moveit_pro_controllers_msgs/AdmittanceParameters``; None when no axis is selected.

        Raises:
            AdmittanceError: a selected axis has a mass that is not positive, or a negative stiffness or
                damping ratio.
        """
        selected = np.array([bool(getattr(message.selected_axes, axis)) for axis in AXES])
        if not selected.any():
            return None

        def six(position: Any, rotation: Any) -> np.ndarray:
            return np.array(
                [position.x, position.y, position.z, rotation.x, rotation.y, rotation.z], dtype=float
            )

        mass = six(message.mass_position, message.mass_rotation)
        stiffness = six(message.stiffness_position, message.stiffness_rotation)
        ratio = six(message.damping_ratio_position, message.damping_ratio_rotation)
        problems = [
            f"{what} {AXES[i]} = {values[i]:g} ({rule})"
            for what, values, bad, rule in (
                ("mass", mass, ~(mass > 0), "must be positive"),
                ("stiffness", stiffness, ~(stiffness >= 0), "must not be negative"),
                ("damping ratio", ratio, ~(ratio >= 0), "must not be negative"),
            )
            for i in np.flatnonzero(bad & selected)
        ]
        joint_damping = float(message.joint_damping)
        if not joint_damping >= 0:
            problems.append(f"joint_damping = {joint_damping:g} (must not be negative)")
        if problems:
            raise AdmittanceError("admittance parameters: " + "; ".join(problems))
        return cls(
            selected=selected,
            mass=np.where(selected, mass, 1.0),
            stiffness=np.where(selected, stiffness, 0.0),
            damping_ratio=np.where(selected, ratio, 0.0),
            joint_damping=joint_damping,
            control_frame=str(message.control_frame),
        )


class ControlFrame:
    """A MuJoCo site or body whose pose and Jacobian the admittance uses.

    Raises:
        AdmittanceError: ``name`` is neither a site nor a body of the model (the message lists the sites).
    """

    def __init__(self, model: Any, name: str) -> None:
        import mujoco

        self.name = name
        self.site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name)
        self.body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
        if self.site < 0 and self.body < 0:
            sites = [model.site(i).name for i in range(model.nsite)]
            raise AdmittanceError(
                f"control frame {name!r} is neither a site nor a body of the MuJoCo scene; sites: "
                f"{', '.join(s for s in sites if s) or 'none'}"
            )

    def pose(self, data: Any) -> tuple[np.ndarray, np.ndarray]:
        """``world_T_frame`` as (position (3,), rotation (3, 3))."""
        if self.site >= 0:
            return data.site_xpos[self.site], data.site_xmat[self.site].reshape(3, 3)
        return data.xpos[self.body], data.xmat[self.body].reshape(3, 3)

    def jacobian(self, model: Any, data: Any, dofs: np.ndarray) -> np.ndarray:
        """The (6, len(dofs)) world-frame Jacobian (linear; angular) of the frame's origin."""
        import mujoco

        jacp = np.zeros((3, model.nv))
        jacr = np.zeros((3, model.nv))
        if self.site >= 0:
            mujoco.mj_jacSite(model, data, jacp, jacr, self.site)
        else:
            mujoco.mj_jacBody(model, data, jacp, jacr, self.body)
        return np.vstack((jacp[:, dofs], jacr[:, dofs]))


class Admittance:
    """The admittance state of one running goal: the Cartesian offset and the joint offset it makes.

    Args:
        parameters: the goal's compliance.
        frame: the control frame.
        dofs: MuJoCo dof addresses of the goal's joints.
        lower, upper: the joints' position limits (the offset never takes a set point past them).
        jacobian_damping: the damping of the least-squares inverse.
    """

    def __init__(
        self,
        parameters: AdmittanceParameters,
        frame: ControlFrame,
        dofs: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        jacobian_damping: float,
    ) -> None:
        self.parameters = parameters
        self.frame = frame
        self.dofs = dofs
        self.lower, self.upper = lower, upper
        self.damping2 = jacobian_damping * jacobian_damping
        self.x = np.zeros(6)  # the Cartesian offset, in the control frame
        self.v = np.zeros(6)
        self.joint_offset = np.zeros(len(dofs))
        self.joint_velocity = np.zeros(len(dofs))
        self._damping = parameters.damping

    def step(self, model: Any, data: Any, wrench: np.ndarray, reference: np.ndarray, dt: float) -> np.ndarray:
        """Advance by ``dt`` under ``wrench`` (force, torque on the tool at the control frame, world frame).

        ``reference`` is the trajectory's set point of the goal's joints now. Returns the joint offset.
        """
        p = self.parameters
        _, rotation = self.frame.pose(data)
        local = np.concatenate((rotation.T @ wrench[:3], rotation.T @ wrench[3:]))
        force = np.where(p.selected, local, 0.0)
        # Backward Euler of M dv = (F - D v - K x) dt, x += v dt: stable at any step.
        v = (p.mass * self.v + dt * (force - p.stiffness * self.x)) / (
            p.mass + dt * self._damping + dt * dt * p.stiffness
        )
        self.v = np.where(p.selected, v, 0.0)
        self.x = self.x + dt * self.v
        twist = np.concatenate((rotation @ self.v[:3], rotation @ self.v[3:]))
        jacobian = self.frame.jacobian(model, data, self.dofs)
        gram = jacobian @ jacobian.T + self.damping2 * np.eye(6)
        inverse = jacobian.T @ np.linalg.inv(gram)
        velocity = inverse @ twist
        if p.joint_damping > 0.0:
            null = self.joint_offset - inverse @ (jacobian @ self.joint_offset)
            velocity = velocity - p.joint_damping * null
        offset = np.clip(self.joint_offset + dt * velocity, self.lower - reference, self.upper - reference)
        self.joint_velocity = (offset - self.joint_offset) / dt
        self.joint_offset = offset
        return offset


def wrench_at(
    sensor_wrench: np.ndarray,
    sensor_position: np.ndarray,
    sensor_rotation: np.ndarray,
    frame_position: np.ndarray,
) -> np.ndarray:
    """A wrench measured at the sensor (sensor frame) as the same wrench about ``frame_position``, world
    frame: the torque picks up ``(sensor - frame) x force``."""
    force = sensor_rotation @ sensor_wrench[:3]
    torque = sensor_rotation @ sensor_wrench[3:] + np.cross(sensor_position - frame_position, force)
    return np.concatenate((force, torque))
