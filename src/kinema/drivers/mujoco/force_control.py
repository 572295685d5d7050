"""The wrist force/torque sensor and the controllers that use it, as MoveIt Pro's lab_sim serves them.

- :class:`ForceTorqueSensor` reads a MuJoCo ``<force>``/``<torque>`` sensor pair on a site (lab_sim's
  ``tcp_fts_sensor`` at ``tool0``). Its wrench is MuJoCo's: the force and torque the arm exerts on the
  tool through the sensor, in the site's frame. At rest it carries the tool's weight (a hanging 0.72 kg
  gripper reads +7.1 N along the world's up axis); pressing the tool onto the table lowers it.
- :class:`ForceTorqueSensorBroadcaster` is ros2_controllers' broadcaster of that wrench
  (``geometry_msgs/WrenchStamped`` on ``/force_torque_sensor_broadcaster/wrench``).
- :class:`VelocityForceController` is MoveIt Pro's hybrid Cartesian velocity/force controller
  (``velocity_force_controller``): each command (``/velocity_force_controller/command``) selects, per
  Cartesian axis of the control frame (the end effector's site), velocity control (move at the commanded
  twist) or force control (move at ``wrench_gain * (wrench - applied)``, where ``applied`` is the wrench the
  tool applies to its surroundings, measured by the sensor since it was last zeroed). The Cartesian
  velocity is limited in speed and acceleration, turned into joint velocities by damped least squares on
  MuJoCo's site Jacobian, limited per joint, and integrated into position set points. Commands must keep
  coming: when none arrived for ``command_timeout`` of sim time the arm decelerates to a stop and holds.
  ``zero_fts`` (a ``std_srvs/Trigger`` service) takes the current reading as the zero; activation does too.
- :class:`JointTrajectoryAdmittanceController` is MoveIt Pro's joint trajectory admittance controller
  (``joint_trajectory_admittance_controller``, "JTAC"): it tracks trajectories like
  ``joint_trajectory_controller`` and serves two goal types under ``/<controller>/follow_joint_trajectory``:
  ``control_msgs/FollowJointTrajectory`` (tracked rigidly) and
  ``moveit_pro_controllers_msgs/FollowJointTrajectoryWithAdmittance``, whose goal carries the admittance
  parameters (the trajectory gives way to the measured wrench as a mass-spring-damper in the control frame,
  :mod:`kinema.drivers.mujoco.admittance`) and the absolute force/torque threshold of that goal. Either goal
  aborts when the wrench the surroundings apply to the tool (the reading less the tool's weight, counted
  from the sensor's zero) passes the threshold on any axis of the sensor frame (default 45 N and 10 N m,
  MoveIt Pro's ``default_absolute_force_torque_threshold``). ``/<controller>/zero_fts/<sensor frame>``
  (``std_srvs/Trigger``) takes the current reading as the zero; activation does too.

All methods but :meth:`VelocityForceController.set_command` run on the physics thread.
"""

from __future__ import annotations

import logging
import threading
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinema.drivers.mujoco.admittance import (
    Admittance,
    AdmittanceError,
    AdmittanceParameters,
    ControlFrame,
    wrench_at,
)
from kinema.drivers.mujoco.controller_manager import Broadcaster
from kinema.drivers.mujoco.execution import Execution
from kinema.drivers.mujoco.model_index import JointInfo
from kinema.drivers.mujoco.trajectory_controller import JointTrajectoryController
from kinema.drivers.mujoco.trajectory_goal import INVALID_GOAL, PATH_TOLERANCE_VIOLATED, TrajectoryGoal
from kinema.transforms import rotate_twist

log = logging.getLogger(__name__)

AXES = ("x", "y", "z", "rx", "ry", "rz")


class ForceTorqueSensor:
    """A MuJoCo force and torque sensor on one site, read as a 6-vector (force, torque) in the site frame.

    Args:
        model: the MuJoCo model.
        name: the sensor's name as ros2_control knows it (the site's name; lab_sim: ``tcp_fts_sensor``).
        frame_id: the frame the readings are published in (the link the site sits on).
    """

    def __init__(self, model: Any, name: str, frame_id: str) -> None:
        self.name = name
        self.frame_id = frame_id
        self.site = int(model.site(name).id)
        force, torque = model.sensor(f"{name}_force"), model.sensor(f"{name}_torque")
        self._force = slice(int(force.adr[0]), int(force.adr[0]) + 3)
        self._torque = slice(int(torque.adr[0]), int(torque.adr[0]) + 3)

    @staticmethod
    def present(model: Any, name: str) -> bool:
        """True when ``model`` has the site ``name`` and the sensors ``<name>_force`` / ``<name>_torque``."""
        import mujoco

        return all(
            mujoco.mj_name2id(model, kind, item) >= 0
            for kind, item in (
                (mujoco.mjtObj.mjOBJ_SITE, name),
                (mujoco.mjtObj.mjOBJ_SENSOR, f"{name}_force"),
                (mujoco.mjtObj.mjOBJ_SENSOR, f"{name}_torque"),
            )
        )

    @property
    def interfaces(self) -> list[str]:
        """``<sensor>/force.x`` ... ``<sensor>/torque.z``, as ros2_control names them."""
        return [f"{self.name}/{kind}.{axis}" for kind in ("force", "torque") for axis in "xyz"]

    def read(self, data: Any) -> np.ndarray:
        """Force (N) and torque (N m) in the site frame."""
        return np.concatenate((data.sensordata[self._force], data.sensordata[self._torque]))

    def gravity_load(self, model: Any, data: Any) -> np.ndarray:
        """What the sensor reads when it only holds the tool up (6,), in the site frame: the weight of the
        bodies below it (the model's masses, so a held object is not included) and its moment about the
        site."""
        body = int(model.site_bodyid[self.site])
        rotation = data.site_xmat[self.site].reshape(3, 3)
        force = -float(model.body_subtreemass[body]) * np.asarray(model.opt.gravity, dtype=float)
        torque = np.cross(data.subtree_com[body] - data.site_xpos[self.site], force)
        return np.concatenate((rotation.T @ force, rotation.T @ torque))


class ForceTorqueSensorBroadcaster(Broadcaster):
    """Publishes the sensor's wrench while active."""

    type_name = "force_torque_sensor_broadcaster/ForceTorqueSensorBroadcaster"

    def __init__(self, name: str, sensor: ForceTorqueSensor) -> None:
        super().__init__(name)
        self.sensor = sensor

    @property
    def state_interfaces(self) -> list[str]:
        """The sensor's six interfaces."""
        return self.sensor.interfaces

    def message(self, data: Any) -> dict[str, Any]:
        """The ``geometry_msgs/WrenchStamped`` of the current reading."""
        wrench = self.sensor.read(data)
        sec, nanosec = self.stamp(data)
        return {
            "header": {"stamp": {"sec": sec, "nanosec": nanosec}, "frame_id": self.sensor.frame_id},
            "wrench": {
                "force": dict(zip("xyz", wrench[:3].tolist(), strict=True)),
                "torque": dict(zip("xyz", wrench[3:].tolist(), strict=True)),
            },
        }

    @staticmethod
    def stamp(data: Any) -> tuple[int, int]:
        """The header stamp of the current reading (sec, nanosec)."""
        now = float(data.time)
        return int(now), round((now % 1.0) * 1e9) % 1_000_000_000


@dataclass(frozen=True)
class VelocityForceLimits:
    """The controller's limits and tuning (lab_sim's values in MoveIt Pro's velocity_force_controller)."""

    max_linear_velocity: float = 0.25  # m/s
    max_angular_velocity: float = 1.0  # rad/s
    max_linear_acceleration: float = 2.0  # m/s^2
    max_angular_acceleration: float = 4.0  # rad/s^2
    max_joint_velocity: float = 1.0  # rad/s (m/s for a prismatic joint)
    max_joint_acceleration: float = 2.0
    force_deadband: float = 2.0  # N: measured forces below this count as none
    torque_deadband: float = 1.0  # N m
    jacobian_damping: float = 0.002
    command_timeout: float = 0.2  # s of sim time
    joint_limit_margin: float = 0.02  # rad (m): no motion toward a limit closer than this
    # The set point never leads the joints by more than this (rad or m): pressing against an obstacle
    # bounds the force instead of winding the set point up.
    max_lead: float = 0.05


@dataclass(frozen=True)
class VelocityForceCommand:
    """One command, as plain arrays (parsed on the transport thread)."""

    twist: np.ndarray  # (6,) linear, angular, in the control frame
    wrench: np.ndarray  # (6,) force, torque the tool should apply, in the control frame
    velocity_axes: np.ndarray  # (6,) bool
    force_axes: np.ndarray  # (6,) bool
    wrench_gain: float

    @classmethod
    def from_message(cls, message: Any) -> VelocityForceCommand:
        """Read a ``moveit_pro_controllers_msgs/VelocityForceCommand``."""
        twist, wrench = message.twist, message.wrench

        def vector(a: Any, b: Any) -> np.ndarray:
            return np.array([a.x, a.y, a.z, b.x, b.y, b.z], dtype=float)

        def axes(selection: Any) -> np.ndarray:
            return np.array([bool(getattr(selection, axis)) for axis in AXES])

        velocity_axes = axes(message.velocity_controlled_axes)
        force_axes = axes(message.force_controlled_axes) & ~velocity_axes
        return cls(
            vector(twist.linear, twist.angular),
            vector(wrench.force, wrench.torque),
            velocity_axes,
            force_axes,
            float(message.wrench_gain),
        )


class VelocityForceController:
    """MoveIt Pro's ``velocity_force_controller`` on position actuators (see the module docstring).

    Args:
        name: the controller's name.
        model: the MuJoCo model.
        joints: the arm's joints (each with a position actuator).
        feedforward: ``kv/kp`` of each joint's actuator (the velocity feed-forward of the set point).
        control_site: the MuJoCo site of the control frame (lab_sim: ``grasp_site``, at ``grasp_link``).
        sensor: the wrist force/torque sensor.
        limits: limits and tuning.
    """

    type_name = "velocity_force_controller/VelocityForceController"

    def __init__(
        self,
        name: str,
        model: Any,
        joints: list[JointInfo],
        feedforward: np.ndarray,
        control_site: str,
        sensor: ForceTorqueSensor,
        limits: VelocityForceLimits | None = None,
    ) -> None:
        self.name = name
        self.model = model
        self.joints = joints
        self.joint_names = [joint.name for joint in joints]
        self.sensor = sensor
        self.limits = limits or VelocityForceLimits()
        self.active = False
        self.dt = float(model.opt.timestep)
        self._site = int(model.site(control_site).id)
        self._qpos = np.array([joint.qpos_address for joint in joints], dtype=int)
        self._dofs = np.array([joint.dof_address for joint in joints], dtype=int)
        self._ctrl = np.array([joint.actuator for joint in joints], dtype=int)
        self._feedforward = np.asarray(feedforward, dtype=float)
        lower = np.array([j.limits[0] if j.limits else -np.inf for j in joints], dtype=float)
        upper = np.array([j.limits[1] if j.limits else np.inf for j in joints], dtype=float)
        self._lower, self._upper = lower, upper
        self._jacp = np.zeros((3, model.nv))
        self._jacr = np.zeros((3, model.nv))
        self._set_point = np.zeros(len(joints))
        self._joint_velocity = np.zeros(len(joints))
        self._cartesian_velocity = np.zeros(6)  # in the world frame
        self._zero = np.zeros(6)
        # The newest command and the sim time it was first seen (set by the transport thread).
        self._lock = threading.Lock()
        self._pending: VelocityForceCommand | None = None
        self._command: VelocityForceCommand | None = None
        self._command_time = -np.inf

    @property
    def command_interfaces(self) -> list[str]:
        """``<joint>/position`` for each arm joint."""
        return [f"{name}/position" for name in self.joint_names]

    @property
    def state_interfaces(self) -> list[str]:
        """Position and velocity of each joint, and the sensor."""
        joints = [f"{name}/{kind}" for name in self.joint_names for kind in ("position", "velocity")]
        return joints + self.sensor.interfaces

    # -- lifecycle -------------------------------------------------------------------------------

    def activate(self, data: Any) -> None:
        """Start commanding: hold where the arm is, take the sensor's reading as its zero, forget commands."""
        self.active = True
        with self._lock:
            self._pending = None
        self._command = None
        self._command_time = -np.inf
        self._hold(data)
        self.zero_sensor(data)

    def deactivate(self, data: Any) -> None:
        """Stop commanding (the actuators keep their last set point)."""
        self.active = False

    def on_state_reset(self, data: Any) -> None:
        """The simulation state was set from outside: hold the new positions, drop the running command."""
        self._command = None
        self._hold(data)

    def shutdown(self, reason: str) -> None:
        """The driver stops (nothing to finish: commands are fire-and-forget)."""

    def post_feedback(self, data: Any) -> None:
        """No goal runs here: nothing to post."""

    # -- inputs ----------------------------------------------------------------------------------

    def set_command(self, message: Any) -> None:
        """A command arrived (transport thread)."""
        command = VelocityForceCommand.from_message(message)
        with self._lock:
            self._pending = command

    def zero_sensor(self, data: Any) -> str:
        """Take the sensor's current reading as its zero (the ``zero_fts`` service); returns a summary."""
        self._zero = self.sensor.read(data)
        force = np.linalg.norm(self._zero[:3])
        torque = np.linalg.norm(self._zero[3:])
        return f"force/torque sensor zeroed (offset {force:.2f} N, {torque:.3f} N m)"

    def applied_wrench(self, data: Any) -> np.ndarray:
        """The wrench the tool applies to its surroundings, in the world frame at the control site (6,).

        The sensor's change since its zero, with the deadband; the torque is taken about the control site.
        """
        change = self.sensor.read(data) - self._zero
        rotation = data.site_xmat[self.sensor.site].reshape(3, 3)
        force_on_tool = rotation @ change[:3]
        torque_on_tool = rotation @ change[3:]
        # The arm's extra push on the tool is what the tool passes on to what it touches.
        offset = data.site_xpos[self.sensor.site] - data.site_xpos[self._site]
        torque_at_site = torque_on_tool + np.cross(offset, force_on_tool)
        return np.concatenate(
            (
                _deadband(force_on_tool, self.limits.force_deadband),
                _deadband(torque_at_site, self.limits.torque_deadband),
            )
        )

    # -- the control period ----------------------------------------------------------------------

    def update(self, data: Any) -> None:
        """One control period: command the joints from the newest command (or stop without one)."""
        if not self.active:
            return
        now = float(data.time)
        with self._lock:
            pending, self._pending = self._pending, None
        if pending is not None:
            self._command, self._command_time = pending, now
        command = self._command
        rotation = data.site_xmat[self._site].reshape(3, 3)
        if command is None or now - self._command_time > self.limits.command_timeout:
            desired_world = np.zeros(6)
        else:
            desired = np.where(command.velocity_axes, command.twist, 0.0)
            if command.force_axes.any():
                applied = self.applied_wrench(data)
                applied_local = rotate_twist(rotation.T, applied)
                force_velocity = command.wrench_gain * (command.wrench - applied_local)
                desired = np.where(command.force_axes, force_velocity, desired)
            desired_world = rotate_twist(rotation, desired)
        velocity = self._limit_cartesian(desired_world)
        self._cartesian_velocity = velocity
        joint_velocity = self._joint_velocities(data, velocity)
        self._integrate(data, joint_velocity)

    def _limit_cartesian(self, desired: np.ndarray) -> np.ndarray:
        limits = self.limits
        linear = _clip_norm(desired[:3], limits.max_linear_velocity)
        angular = _clip_norm(desired[3:], limits.max_angular_velocity)
        previous = self._cartesian_velocity
        linear = previous[:3] + _clip_norm(linear - previous[:3], limits.max_linear_acceleration * self.dt)
        angular = previous[3:] + _clip_norm(angular - previous[3:], limits.max_angular_acceleration * self.dt)
        return np.concatenate((linear, angular))

    def _joint_velocities(self, data: Any, velocity: np.ndarray) -> np.ndarray:
        if not velocity.any():
            return np.zeros(len(self.joints))
        import mujoco

        mujoco.mj_jacSite(self.model, data, self._jacp, self._jacr, self._site)
        jacobian = np.vstack((self._jacp[:, self._dofs], self._jacr[:, self._dofs]))
        damping = self.limits.jacobian_damping
        gram = jacobian @ jacobian.T + (damping * damping) * np.eye(6)
        return jacobian.T @ np.linalg.solve(gram, velocity)

    def _integrate(self, data: Any, joint_velocity: np.ndarray) -> None:
        limits = self.limits
        # Joint speed: scale the whole vector (keeps the Cartesian direction); then joint acceleration.
        peak = float(np.max(np.abs(joint_velocity))) if len(joint_velocity) else 0.0
        if peak > limits.max_joint_velocity:
            joint_velocity = joint_velocity * (limits.max_joint_velocity / peak)
        step = limits.max_joint_acceleration * self.dt
        joint_velocity = self._joint_velocity + np.clip(joint_velocity - self._joint_velocity, -step, step)
        # No motion toward a joint limit closer than the margin.
        position = self._set_point
        blocked = ((position <= self._lower + limits.joint_limit_margin) & (joint_velocity < 0)) | (
            (position >= self._upper - limits.joint_limit_margin) & (joint_velocity > 0)
        )
        joint_velocity = np.where(blocked, 0.0, joint_velocity)
        actual = data.qpos[self._qpos]
        set_point = np.clip(
            position + joint_velocity * self.dt, actual - limits.max_lead, actual + limits.max_lead
        )
        self._joint_velocity = joint_velocity
        self._set_point = set_point
        data.ctrl[self._ctrl] = set_point + self._feedforward * joint_velocity

    def _hold(self, data: Any) -> None:
        self._set_point = data.qpos[self._qpos].copy()
        self._joint_velocity = np.zeros(len(self.joints))
        self._cartesian_velocity = np.zeros(6)
        data.ctrl[self._ctrl] = self._set_point


def _clip_norm(vector: np.ndarray, limit: float) -> np.ndarray:
    norm = float(np.linalg.norm(vector))
    return vector * (limit / norm) if norm > limit else vector


def _deadband(vector: np.ndarray, band: float) -> np.ndarray:
    """``vector`` shortened by ``band`` (zero when shorter): no jump where the band ends."""
    norm = float(np.linalg.norm(vector))
    return vector * ((norm - band) / norm) if norm > band else np.zeros(3)


class JointTrajectoryAdmittanceController(JointTrajectoryController):
    """``joint_trajectory_controller`` with compliance and a force/torque guard (see the module docstring).

    Args:
        sensor: the wrist force/torque sensor.
        model: the MuJoCo model (the control frame's Jacobian).
        control_frame: the MuJoCo site or body the admittance acts in when a goal names none (the config's
            ``robot.force_torque_sensor.control_site``; "" for none: such goals are rejected).
        threshold: the default largest force (N) and torque (N m) on each axis of the sensor frame, counted
            from the sensor's zero (MoveIt Pro's ``default_absolute_force_torque_threshold``).
        jacobian_damping: the damping of the least-squares inverse (lab_sim's value in MoveIt Pro).
        others: as :class:`JointTrajectoryController`.
    """

    type_name = "joint_trajectory_admittance_controller/JointTrajectoryAdmittanceController"

    def __init__(
        self,
        *args: Any,
        sensor: ForceTorqueSensor,
        model: Any,
        control_frame: str = "",
        threshold: tuple[float, ...] = (45.0, 45.0, 45.0, 10.0, 10.0, 10.0),
        jacobian_damping: float = 0.01,
        **kwargs: Any,
    ) -> None:
        super().__init__(*args, **kwargs)
        self.sensor = sensor
        self.model = model
        self.control_frame = control_frame
        self.default_threshold = np.asarray(threshold, dtype=float)
        self.jacobian_damping = jacobian_damping
        self._threshold = self.default_threshold
        # The reading, less the tool's weight, taken as zero (activation, the zero_fts service).
        self._zero = np.zeros(6)
        self._admittance: Admittance | None = None
        self._lower = np.array([j.limits[0] if j.limits else -np.inf for j in self.joints], dtype=float)
        self._upper = np.array([j.limits[1] if j.limits else np.inf for j in self.joints], dtype=float)

    @property
    def state_interfaces(self) -> list[str]:
        """Position and velocity of each joint, and the sensor."""
        return super().state_interfaces + self.sensor.interfaces

    @property
    def compliant(self) -> bool:
        """True while a goal runs with admittance."""
        return self._admittance is not None

    def activate(self, data: Any) -> None:
        """Start commanding (hold where the arm is) and take the sensor's reading as its zero."""
        super().activate(data)
        self.zero_sensor(data)

    def zero_sensor(self, data: Any) -> str:
        """Take the current reading (less the tool's weight) as the zero (``zero_fts``); returns a summary."""
        reading = self.sensor.read(data)
        self._zero = reading - self.sensor.gravity_load(self.model, data)
        force, torque = np.linalg.norm(reading[:3]), np.linalg.norm(reading[3:])
        return f"force/torque sensor {self.sensor.name} zeroed (reading {force:.2f} N, {torque:.3f} N m)"

    def external_wrench(self, data: Any) -> np.ndarray:
        """The wrench the surroundings apply to the tool, in the sensor frame (6,): the reading less the
        tool's weight, less the zero, with the sign turned (the sensor reads the arm's push on the tool)."""
        return -(self.sensor.read(data) - self.sensor.gravity_load(self.model, data) - self._zero)

    def start(
        self,
        execution: Execution,
        goal: TrajectoryGoal,
        data: Any,
        admittance: AdmittanceParameters | None = None,
        threshold: np.ndarray | None = None,
    ) -> None:
        """Begin tracking ``goal`` with ``admittance`` (None: rigidly) and ``threshold`` (None: default)."""
        frame = None
        if admittance is not None:
            name = admittance.control_frame or self.control_frame
            if not name:
                execution.finish(
                    "aborted",
                    {
                        "error_code": INVALID_GOAL,
                        "error_string": f"{self.name} has no control frame: the admittance parameters name "
                        "none and the config sets no robot.force_torque_sensor.control_site",
                    },
                )
                return
            try:
                frame = ControlFrame(self.model, name)
            except AdmittanceError as error:
                execution.finish("aborted", {"error_code": INVALID_GOAL, "error_string": str(error)})
                return
        super().start(execution, goal, data)
        running = self._running
        if running is None or running.execution is not execution:
            return
        self._threshold = self.default_threshold if threshold is None else np.asarray(threshold, dtype=float)
        if admittance is None or frame is None:
            self._admittance = self._offset = self._offset_command = None
            return
        columns = goal.joint_indices
        self._admittance = Admittance(
            admittance,
            frame,
            self._qvel[columns],
            self._lower[columns],
            self._upper[columns],
            self.jacobian_damping,
        )
        self._offset = np.zeros(len(columns))
        self._offset_command = np.zeros(len(columns))

    def update(self, data: Any) -> None:
        """One control period: the guard, the admittance, then the trajectory."""
        running = self._running
        if running is not None:
            external = self.external_wrench(data)
            over = np.abs(external) > self._threshold
            if over.any():
                names = [f"{'force' if i < 3 else 'torque'} {'xyz'[i % 3]}" for i in np.flatnonzero(over)]
                self._fail(
                    data,
                    PATH_TOLERANCE_VIOLATED,
                    "force/torque threshold exceeded",
                    [
                        f"{name} {external[i]:+.1f} (limit {self._threshold[i]:g})"
                        for name, i in zip(names, np.flatnonzero(over), strict=True)
                    ],
                )
                return
            admittance = self._admittance
            elapsed = float(data.time) - running.start
            if admittance is not None and elapsed >= 0.0:
                reference = running.table.positions[running.table.index_at(elapsed)]
                frame_position, _ = admittance.frame.pose(data)
                wrench = wrench_at(
                    external,
                    data.site_xpos[self.sensor.site],
                    data.site_xmat[self.sensor.site].reshape(3, 3),
                    frame_position,
                )
                offset = admittance.step(self.model, data, wrench, reference, self.dt)
                columns = running.goal.joint_indices
                self._offset_command = offset + self._feedforward[columns] * admittance.joint_velocity
                # The tolerances compare the joints with the compliant set point where the position servos
                # hold them under the measured load: a servo gives tau / kp (MuJoCo's actuators are far
                # softer than a real arm's, and a held push would otherwise fail the goal tolerance).
                self._offset = offset + self._servo_give(data, external, columns)
        super().update(data)

    def _servo_give(self, data: Any, external: np.ndarray, columns: np.ndarray) -> np.ndarray:
        """How far the goal's joints give under ``external`` (the sensor-frame wrench on the tool)."""
        if self._gains is None:
            return np.zeros(len(columns))
        import mujoco

        jacp = np.zeros((3, self.model.nv))
        jacr = np.zeros((3, self.model.nv))
        mujoco.mj_jacSite(self.model, data, jacp, jacr, self.sensor.site)
        rotation = data.site_xmat[self.sensor.site].reshape(3, 3)
        dofs = self._qvel[columns]
        torque = jacp[:, dofs].T @ (rotation @ external[:3]) + jacr[:, dofs].T @ (rotation @ external[3:])
        return np.asarray(torque / self._gains[columns])

    def _end(self, data: Any, status: Any, result: dict[str, Any], *, hold: bool) -> None:
        super()._end(data, status, result, hold=hold)
        if self._running is None:
            self._admittance = self._offset = self._offset_command = None
