"""The control loop MoveIt Pro's three MPC behaviors share, on :class:`kinema.motion.mpc.PoseTrackingMpc`.

MoveIt Pro's MPC behaviors run a sampling planner (MuJoCo MPC's predictive sampling) on a simplified
MuJoCo model and send its plan to the joint trajectory controller. Kinema solves a QP per step instead
(:mod:`kinema.motion.mpc`: joint, velocity and clearance constraints, ProxQP on pinocchio's kinematics of
the config's robot model). The ports are MoveIt Pro's; those that tune the sampling planner or name its
MuJoCo model are accepted and not used, and each port's description says what Kinema does with it.

Every ``timestep`` of the runtime clock (sim time in simulation) the loop reads the latest
``/joint_states``, the target pose and twist (again each step, so a tree may move the target while the
behavior runs) and the obstacles, solves, and streams the plan to the trajectory controller named by
``follow_joint_trajectory_topic`` on that controller's ``joint_trajectory`` topic (stamped with the joint
state's time, so the controller starts it where the robot was measured; each plan replaces the last).
When solving takes longer than a timestep the loop runs as fast as it can and the plan, which covers the
whole horizon, keeps the arm moving meanwhile. The solver runs on wall time: a simulation faster than real
time (``--sim-speed``) leaves it behind, so run MPC objectives at real time (the default).

The behavior stays RUNNING until halted (a ``Timeout`` or a ``Parallel``) and succeeds after ``timeout``
seconds; halting it, its timeout and any failure stop the arm (an empty trajectory: the controller brakes
and holds).
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from kinema.behaviors import AsyncBehavior, PortInfo, input_port, output_port
from kinema.behaviors.cell_ports import cell_input_port
from kinema.errors import KinemaError, ObjectiveError

from ..messages.conversions import POSE_STAMPED_TYPE, duration, pose_matrix
from ..messages.ports import message_input, read_message
from ..motion.joint_states import joint_state_monitor
from ..motion.planning_resources import robot_model

if TYPE_CHECKING:
    import numpy as np

    from kinema.motion.mpc import MpcPlan, MpcSettings, Obstacles

JOINT_TRAJECTORY_TYPE = "trajectory_msgs/msg/JointTrajectory"
TWIST_STAMPED_TYPE = "geometry_msgs/msg/TwistStamped"
UNUSED = "Tunes MoveIt Pro's sampling planner; Kinema's MPC is a QP and accepts the value without using it."
# How long (wall time) the loop waits for the clock at most before checking for a halt again.
_POLL = 0.05


def streaming_topic(action: str) -> str:
    """``/<controller>/joint_trajectory`` for ``/<controller>/follow_joint_trajectory``.

    Raises:
        ObjectiveError: ``action`` is not a controller's FollowJointTrajectory action name.
    """
    parts = action.strip().strip("/").split("/")
    if len(parts) != 2 or parts[1] != "follow_joint_trajectory" or not parts[0]:
        raise ObjectiveError(
            f"follow_joint_trajectory_topic {action!r} is not a trajectory controller's action; expected "
            "/<controller>/follow_joint_trajectory, e.g. /joint_trajectory_controller/follow_joint_trajectory"
        )
    return f"/{parts[0]}/joint_trajectory"


def common_ports(horizon: float, site_tracking: float, warmup: int) -> list[PortInfo]:
    """The ports all three behaviors have (defaults: the values lab_sim's objectives use)."""
    return [
        message_input(
            "target_pose",
            POSE_STAMPED_TYPE,
            "{target_pose}",
            "Where gripper_site_name should be; read again every step, so the tree may move it.",
        ),
        message_input(
            "target_twist",
            TWIST_STAMPED_TYPE,
            "{target_twist}",
            "The target's velocity (linear m/s, angular rad/s, in its header's frame): the plan expects "
            "the target to move on at it over the horizon. Read every step; unset: a still target.",
        ),
        cell_input_port("planning_group", str, "planning_group", "The planning group that moves."),
        cell_input_port(
            "gripper_site_name",
            str,
            "tool_frame",
            "The frame that tracks the target: a MuJoCo site in MoveIt Pro, a link or frame of the robot "
            "model in Kinema (lab_sim has MoveIt Pro's site names: pinch, attachment_site, base_site).",
        ),
        input_port(
            "horizon",
            float,
            horizon,
            "Seconds planned ahead each step (a trailing ';', as MoveIt Pro's files write it, is fine).",
        ),
        input_port("timestep", float, 0.01, "Seconds between planned points, and between control steps."),
        input_port(
            "site_tracking",
            float,
            site_tracking,
            "Weight of the tracking cost (position per m; orientation per rad at a quarter of it).",
        ),
        input_port(
            "velocity",
            float,
            0.0,
            "Weight of a cost on joint speed, added to Kinema's small smoothing cost (0: only that).",
        ),
        input_port(
            "max_velocity_goal",
            float,
            0.0,
            "Joint speed cap (rad/s or m/s) below the joint limits when > 0 and velocity > 0; 0: the "
            "joint limits alone.",
        ),
        input_port(
            "acceleration",
            float,
            0.0,
            "Weight of a cost on joint acceleration, added to Kinema's smoothing cost (the joints' "
            "acceleration limits hold in any case).",
        ),
        input_port(
            "cartesian_velocity",
            float,
            100.0,
            "Turns the Cartesian speed limit on (> 0) or off (0); Kinema enforces it as a constraint.",
        ),
        input_port(
            "max_cartesian_velocity_goal",
            float,
            0.5,
            "Largest linear speed of cartesian_velocity_body, m/s (a hard limit in Kinema).",
        ),
        cell_input_port(
            "cartesian_velocity_body",
            str,
            "tool_frame",
            "The frame whose speed is limited (MoveIt Pro: a MuJoCo body; Kinema: a robot frame).",
        ),
        input_port(
            "cartesian_acceleration",
            float,
            100.0,
            "MoveIt Pro's weight of a Cartesian acceleration cost; Kinema limits joint accelerations "
            "(the model's limits) instead and does not use it.",
        ),
        input_port(
            "max_cartesian_acceleration_goal",
            float,
            500.0,
            "MoveIt Pro's Cartesian acceleration goal, m/s²; not used (see cartesian_acceleration).",
        ),
        cell_input_port(
            "cartesian_acceleration_body",
            str,
            "tool_frame",
            "The body of cartesian_acceleration; not used by Kinema.",
        ),
        input_port(
            "timeout",
            float,
            300.0,
            "Seconds (runtime clock) after which the behavior stops the arm and succeeds.",
        ),
        cell_input_port(
            "follow_joint_trajectory_topic",
            str,
            "trajectory_action",
            "The trajectory controller's FollowJointTrajectory action. Kinema streams each plan to the "
            "same controller's joint_trajectory topic beside it (/<controller>/joint_trajectory), each "
            "replacing the last, rather than sending a goal per step.",
        ),
        input_port(
            "set_ctrl_command_to_current_state",
            bool,
            True,
            "Start from the measured state: Kinema starts every plan at the latest /joint_states.",
        ),
        input_port(
            "mujoco_model",
            str,
            "",
            "MoveIt Pro's simplified MuJoCo model for the planner; Kinema plans on the config's robot "
            "model (pinocchio) and does not read it.",
        ),
        input_port("mujoco_model_package", str, "", "The package of mujoco_model; not read by Kinema."),
        input_port("differentiable", int, 0, UNUSED),
        input_port("gradient_num_trajectory", float, 32.0, UNUSED),
        input_port("gradient_spline_points", float, 1.0, UNUSED),
        input_port("sampling_control_width", float, 0.015, UNUSED),
        input_port("sampling_exploration", float, 0.05, UNUSED),
        input_port("sampling_sample_width", float, 0.01, UNUSED),
        input_port("sampling_spline_points", float, 10.0, UNUSED),
        input_port("warmup_iterations", int, warmup, UNUSED),
        output_port(
            "total_return",
            float,
            "{total_return}",
            "The last plan's tracking cost (weighted squared pose error summed over the horizon).",
        ),
    ]


def clearance_ports(weight_port: str, weight: float, link_sites: str) -> list[PortInfo]:
    """The ports of the two clearance behaviors beyond :func:`common_ports`."""
    return [
        input_port(
            "safe_distance",
            float,
            0.25,
            "Clearance (m) kept between the clearance frames and the obstacles' surfaces: a constraint "
            "in Kinema; where the arm starts closer it comes no closer and backs out.",
        ),
        input_port(
            weight_port,
            float,
            weight,
            "MoveIt Pro's weight of the clearance cost; in Kinema 0 turns the clearance off and any "
            "other value keeps it as a constraint.",
        ),
        input_port(
            "link_sites",
            str,
            link_sites,
            "More frames that keep the clearance besides gripper_site_name, separated by ';' (MoveIt "
            "Pro: MuJoCo sites; Kinema: robot frames).",
        ),
    ]


class MpcControlLoop(AsyncBehavior):
    """The loop of the module docstring; subclasses say what the obstacles are (:meth:`obstacles`)."""

    subcategory = "Motion - Controls"
    #: The port whose weight turns clearance on (None: the behavior keeps no clearance).
    clearance_weight_port: str | None = None

    def __init__(self, name: str, config: Any = None) -> None:
        super().__init__(name, config)
        self._lock = threading.Lock()
        self._halted = False
        self._publisher: Any = None

    # -- what subclasses provide -----------------------------------------------------------------

    def obstacles(self) -> Obstacles | None:
        """The obstacles now, in the world frame (None: none). Called every step, on the worker thread."""
        return None

    # -- the loop --------------------------------------------------------------------------------

    def do_work(self) -> bool:
        with self._lock:
            self._halted = False
        try:
            return self._run()
        except KinemaError as error:
            self._stop_arm()
            self.logger.publish_failure(f"{self.registration_id}: {error}")
            return False

    def do_halt(self) -> None:
        with self._lock:
            self._halted = True
        self._stop_arm()

    def _run(self) -> bool:
        from kinema.motion.mpc import PoseTrackingMpc

        name = self.registration_id
        model = robot_model(self.context, name)
        settings = self._settings()
        mpc = PoseTrackingMpc(model, str(self.get_input("planning_group")), self._site(), settings)
        if float(self.get_input("force_torque") if self._has_port("force_torque") else 0.0):
            self.logger.publish_info(f"{name}: force_torque has no effect in Kinema's MPC (no force model)")
        node = self.context.require_node(name)
        topic = streaming_topic(str(self.get_input("follow_joint_trajectory_topic")))
        self._publisher = self.context.publisher(node, JOINT_TRAJECTORY_TYPE, topic)
        monitor = joint_state_monitor(self.context, name)
        clock = self.context.clock
        timeout = float(self.get_input("timeout"))
        started = clock.now()
        due = started
        errors: list[float] = []
        closest = float("inf")
        plan: MpcPlan | None = None
        while not self.stop_requested():
            now = clock.now()
            if now - started >= timeout:
                break
            if now < due:
                self._sleep(clock, due - now)
                continue
            message = monitor.latest()
            stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
            q = self._positions(message, model.joint_names)
            plan = mpc.step(q, stamp, self._target(), self._twist(), self.obstacles())
            if not self._publish(plan):
                break  # halted meanwhile
            errors.append(plan.position_error)
            closest = min(closest, plan.clearance)
            # The next step's slot on the timestep grid; slots missed while solving are not made up.
            due += settings.timestep * max(1, int((clock.now() - due) / settings.timestep) + 1)
        self._stop_arm()
        if plan is not None:
            halted = self.stop_requested()
            summary = (
                f"{name}: {'halted' if halted else 'done'} after {clock.now() - started:.1f} s "
                f"({len(errors)} steps, {mpc.relaxed_steps} relaxed); position error now "
                f"{1000 * errors[-1]:.1f} mm, median {1000 * sorted(errors)[len(errors) // 2]:.1f} mm"
            )
            if closest < float("inf"):
                summary += (
                    f"; closest to an obstacle {closest:.3f} m (safe distance {settings.safe_distance:g} m)"
                )
            self.logger.publish_info(summary)
            if not halted:
                self.set_output("total_return", plan.cost)
        return not self.stop_requested()

    def _settings(self) -> MpcSettings:
        from kinema.motion.mpc import MpcSettings

        tracking = self._non_negative("site_tracking")
        speed_weight = self._non_negative("velocity")
        speed_cap = self._non_negative("max_velocity_goal")
        cartesian = self._non_negative("cartesian_velocity") > 0
        clearance = (
            self.clearance_weight_port is not None and self._non_negative(self.clearance_weight_port) > 0
        )
        frames: tuple[str, ...] = ()
        if clearance:
            extra = str(self.get_input("link_sites")).replace(",", ";").split(";")
            frames = (self._site(), *(s.strip() for s in extra if s.strip()))
        return MpcSettings(
            horizon=float(self.get_input("horizon")),
            timestep=float(self.get_input("timestep")),
            position_weight=tracking,
            orientation_weight=0.25 * tracking,
            velocity_weight=1e-4 + 1e-3 * speed_weight,
            acceleration_weight=1e-7 + 1e-5 * self._non_negative("acceleration"),
            max_joint_speed=speed_cap if speed_cap > 0 and speed_weight > 0 else None,
            cartesian_frame=str(self.get_input("cartesian_velocity_body")) if cartesian else None,
            max_cartesian_speed=float(self.get_input("max_cartesian_velocity_goal")) if cartesian else None,
            clearance_frames=frames,
            safe_distance=self._non_negative("safe_distance") if clearance else 0.0,
        )

    def _non_negative(self, port: str) -> float:
        value = float(self.get_input(port))
        if not value >= 0:
            raise ObjectiveError(f"port [{port}] = {value:g}; give a value of 0 or more")
        return value

    def _has_port(self, port: str) -> bool:
        return any(p.name == port for p in self.provided_ports())

    def _site(self) -> str:
        return str(self.get_input("gripper_site_name")).strip()

    def _sleep(self, clock: Any, seconds: float) -> None:
        """Wait ``seconds`` of the runtime clock (or until halted, checked every _POLL of wall time)."""
        woken = threading.Event()
        timer = clock.call_later(seconds, woken.set)
        try:
            woken.wait(_POLL)
        finally:
            timer.cancel()

    @staticmethod
    def _positions(message: Any, joint_names: tuple[str, ...]) -> np.ndarray:
        import numpy as np

        index = {str(n): i for i, n in enumerate(message.name)}
        missing = [n for n in joint_names if n not in index]
        if missing:
            raise ObjectiveError(f"/joint_states does not report joint(s) {', '.join(missing)}")
        return np.array([float(message.position[index[n]]) for n in joint_names])

    def _target(self) -> np.ndarray:
        """The target pose in the world frame."""
        frame, matrix = pose_matrix(read_message(self, "target_pose", POSE_STAMPED_TYPE), "target_pose")
        return self._world_T(frame) @ matrix

    def _twist(self) -> np.ndarray | None:
        """The target twist in world axes (None when the port is unset)."""
        import numpy as np

        message = self.get_input_or("target_twist", None)
        if message is None:
            return None
        twist = getattr(message, "twist", None)
        if twist is None:
            raise ObjectiveError(
                "target_twist must be a geometry_msgs/TwistStamped (from CreateTwistStamped)"
            )
        linear, angular = twist.linear, twist.angular
        vector = np.array([linear.x, linear.y, linear.z, angular.x, angular.y, angular.z], dtype=float)
        rotation = self._world_T(str(message.header.frame_id))[:3, :3]
        return np.concatenate((rotation @ vector[:3], rotation @ vector[3:]))

    def _world_T(self, frame: str) -> np.ndarray:
        import numpy as np

        if frame in ("", "world"):
            return np.eye(4)
        from ..poses.frame_tree import current_frame_tree

        return np.asarray(current_frame_tree(self).world_T(frame), dtype=float)

    def _publish(self, plan: MpcPlan) -> bool:
        """Stream ``plan``; False when the behavior was halted meanwhile (nothing is sent then)."""
        from kinema.transport import from_dict

        rows = zip(plan.positions, plan.velocities, plan.times, strict=True)
        message = from_dict(
            JOINT_TRAJECTORY_TYPE,
            {
                "header": {"stamp": duration(plan.start)},
                "joint_names": list(plan.joint_names),
                "points": [
                    {"positions": p.tolist(), "velocities": v.tolist(), "time_from_start": duration(t)}
                    for p, v, t in rows
                ],
            },
        )
        with self._lock:
            if self._halted:
                return False
            self._publisher.publish(message)
        return True

    def _stop_arm(self) -> None:
        """An empty trajectory: the controller brakes and holds."""
        publisher = self._publisher
        if publisher is None:
            return
        from kinema.transport import from_dict

        publisher.publish(from_dict(JOINT_TRAJECTORY_TYPE, {"joint_names": [], "points": []}))
