"""The MuJoCo driver: a simulated robot served as ros2_control-like controllers on the transport.

In-process::

    from kinema.drivers.mujoco import MujocoDriver, MujocoDriverSettings
    from kinema.transport import open_session

    with open_session(endpoint) as session:
        settings = MujocoDriverSettings.from_config("lab_sim", sim_speed=math.inf)
        with MujocoDriver(session, settings) as driver:      # start() ... stop()
            ...

As a process: ``python -m kinema.drivers.mujoco --config lab_sim --sim-speed max`` (see ``--help``).

What it serves (names in :mod:`kinema.drivers.mujoco.names`): ``/clock`` and ``/joint_states`` at the
publish rate of sim time; per controller of the config, by its ros2_control type: ``/<trajectory
controller>/follow_joint_trajectory`` (and its streaming input ``/<trajectory
controller>/joint_trajectory``, each trajectory replacing the last, an empty one stopping the arm) and
``/<gripper controller>/gripper_cmd`` (lab_sim:
``/joint_trajectory_controller/...`` and ``/robotiq_gripper_controller/gripper_cmd``);
``/controller_manager/list_controllers`` and ``/controller_manager/switch_controller(s)``;
``/mujoco/set_state`` (keyframe and/or joint positions), ``/mujoco/bodies`` (free body poses),
``/mujoco/keyframes`` and the ``/mujoco/scene_state`` topic; per camera of the scene ``/<camera>/color``,
``/depth``, ``/camera_info`` and ``/points``, rendered only while subscribed (see
:mod:`kinema.drivers.mujoco.cameras`). With the config's force/torque sensor (lab_sim's ``tcp_fts_sensor``):
``/<broadcaster>/wrench``, the admittance trajectory controller's ``/<controller>/follow_joint_trajectory``
(FollowJointTrajectory and FollowJointTrajectoryWithAdmittance) and ``/<controller>/zero_fts/<sensor frame>``,
and the velocity-force controller's ``/<controller>/command`` and ``/<controller>/zero_fts`` (see
:mod:`kinema.drivers.mujoco.force_control`).
"""

from __future__ import annotations

import functools
import logging
import threading
import time
from collections.abc import Callable, Mapping
from types import SimpleNamespace
from typing import Any

import numpy as np

from kinema.config import cell
from kinema.drivers.mujoco import names
from kinema.drivers.mujoco.admittance import AdmittanceError, AdmittanceParameters, ControlFrame
from kinema.drivers.mujoco.cameras import CameraServer, SimState
from kinema.drivers.mujoco.cdr_templates import (
    ClockEncoder,
    JointStateEncoder,
    WrenchStampedEncoder,
    generic_serializers,
    wrench_serializer,
)
from kinema.drivers.mujoco.contacts import contact_reporter
from kinema.drivers.mujoco.controller_manager import Controller, ControllerManager, JointStateBroadcaster
from kinema.drivers.mujoco.execution import Execution
from kinema.drivers.mujoco.force_control import (
    ForceTorqueSensor,
    ForceTorqueSensorBroadcaster,
    JointTrajectoryAdmittanceController,
    VelocityForceController,
)
from kinema.drivers.mujoco.gripper_controller import GripperController
from kinema.drivers.mujoco.model_index import ModelIndex
from kinema.drivers.mujoco.scene_state import (
    apply_joint_state,
    check_joint_positions,
    free_body_poses,
    reset_to_keyframe,
)
from kinema.drivers.mujoco.settings import MujocoDriverSettings
from kinema.drivers.mujoco.sim_speed import format_sim_speed
from kinema.drivers.mujoco.simulation import Simulation
from kinema.drivers.mujoco.trajectory_controller import JointTrajectoryController
from kinema.drivers.mujoco.trajectory_goal import INVALID_GOAL, GoalRejected, parse_trajectory_goal
from kinema.drivers.protocol import ServedInterface
from kinema.errors import DriverError
from kinema.transport import Node, ServerGoalHandle, Session

log = logging.getLogger("kinema.drivers.mujoco")

# Wall time between feedback messages of a running goal (feedback is posted at the publish rate).
FEEDBACK_PERIOD = 0.05
# How long stop() waits for running goals to send their results.
RESULT_GRACE = 1.0


def _stamp(seconds: float) -> dict[str, int]:
    nanoseconds = round(seconds * 1e9)
    return {"sec": nanoseconds // 1_000_000_000, "nanosec": nanoseconds % 1_000_000_000}


def _admittance_of(goal: Any) -> tuple[AdmittanceParameters | None, np.ndarray | None]:
    """The admittance and threshold of a FollowJointTrajectoryWithAdmittance goal ((None, None) for a
    plain FollowJointTrajectory goal).

    Raises:
        GoalRejected: unusable admittance parameters, or a threshold of another length than 6.
    """
    if not hasattr(goal, "admittance_parameters"):
        return None, None
    try:
        admittance = AdmittanceParameters.from_message(goal.admittance_parameters)
    except AdmittanceError as error:
        raise GoalRejected(INVALID_GOAL, str(error)) from None
    values = [float(v) for v in goal.absolute_force_torque_threshold]
    if not values:
        return admittance, None
    if len(values) != 6 or not all(v > 0 for v in values):
        raise GoalRejected(
            INVALID_GOAL,
            f"absolute_force_torque_threshold must be six positive values fx, fy, fz, tx, ty, tz (N, N m); "
            f"got {values}",
        )
    return admittance, np.array(values)


def _admittance_options(
    name: str, parameters: Mapping[str, Any], control_site: str, model: Any
) -> dict[str, Any]:
    """The admittance controller's options from its ros2_control parameters (MoveIt Pro's names):
    ``default_absolute_force_torque_threshold``, ``jacobian_damping`` and ``ee_frame`` (the control frame
    when the config gives no control site; it must be a site or body of the scene).

    Raises:
        DriverError: a parameter of the wrong shape, naming the controller and the parameter.
    """
    options: dict[str, Any] = {"control_frame": control_site}
    threshold = parameters.get("default_absolute_force_torque_threshold")
    if threshold is not None:
        if (
            not isinstance(threshold, list)
            or len(threshold) != 6
            or not all(isinstance(v, int | float) and not isinstance(v, bool) and v > 0 for v in threshold)
        ):
            raise DriverError(
                f"controller {name!r}: default_absolute_force_torque_threshold must be six positive numbers "
                f"(fx, fy, fz, tx, ty, tz in N and N m), got {threshold!r}"
            )
        options["threshold"] = tuple(float(v) for v in threshold)
    damping = parameters.get("jacobian_damping")
    if damping is not None:
        if isinstance(damping, bool) or not isinstance(damping, int | float) or damping < 0:
            raise DriverError(f"controller {name!r}: jacobian_damping must be a number >= 0, got {damping!r}")
        options["jacobian_damping"] = float(damping)
    ee_frame = str(parameters.get("ee_frame") or "")
    if not control_site and ee_frame:
        try:
            ControlFrame(model, ee_frame)
        except AdmittanceError as error:
            log.warning("controller %r: its ee_frame is no control frame: %s", name, error)
        else:
            options["control_frame"] = ee_frame
    return options


def _load_model(settings: MujocoDriverSettings) -> Any:

    from kinema.config.mujoco_scene import load_scene
    from kinema.errors import ConfigError

    path = settings.model_path
    if not path.is_file():
        raise DriverError(f"MuJoCo scene {path} does not exist")
    try:
        return load_scene(path)
    except ConfigError as error:
        raise DriverError(str(error)) from None


class MujocoDriver:
    """Simulates a MuJoCo scene and serves its controllers (implements :class:`kinema.drivers.Driver`).

    Args:
        session: the transport session to serve on.
        settings: the scene, speed, rates and controllers.

    Raises:
        DriverError: the scene cannot be loaded, or the start keyframe does not exist.
    """

    name = "mujoco"

    def __init__(self, session: Session, settings: MujocoDriverSettings) -> None:
        import mujoco

        self.session = session
        self.settings = settings
        self.model = _load_model(settings)
        self.data = mujoco.MjData(self.model)
        self.index = ModelIndex.from_model(self.model)
        if settings.keyframe:
            reset_to_keyframe(self.model, self.data, self.index, settings.keyframe)
        else:
            mujoco.mj_forward(self.model, self.data)
        self._controllers = self._build_controllers()
        # The controllers that run goals: updated before every step, asked for feedback at every
        # publish (each returns at once when no goal runs), told about resets and shutdown.
        self._goal_controllers: list[
            JointTrajectoryController | GripperController | VelocityForceController
        ] = [
            c
            for c in self._controllers.values()
            if isinstance(c, JointTrajectoryController | GripperController | VelocityForceController)
        ]
        self.controller_manager = ControllerManager(
            list(self._controllers.values()), update_rate=round(1.0 / self.index.timestep)
        )
        self.simulation = Simulation(
            self.model,
            self.data,
            speed=settings.sim_speed,
            publish_period=1.0 / settings.publish_rate,
            before_step=self._before_step,
            on_publish=self._on_publish,
        )
        self._joint_names = self.index.joint_names
        generic_clock, generic_joint_state = generic_serializers(session.registry)
        self._clock_encoder = ClockEncoder(generic_clock)
        self._joint_state_encoder = JointStateEncoder(self._joint_names, generic_joint_state)
        self._joint_qpos = np.array([j.qpos_address for j in self.index.joints], dtype=int)
        self._joint_dofs = np.array([j.dof_address for j in self.index.joints], dtype=int)
        self._nodes: list[Node] = []
        self._publishers: dict[str, Any] = {}
        self._joint_state_broadcaster: Controller | None = None
        # (broadcaster, publisher, its WrenchStamped template) per force/torque broadcaster.
        self._wrench_publishers: list[tuple[Any, Any, WrenchStampedEncoder]] = []
        # Running goals by goal id, with the controller that runs each (for cancel requests).
        self._executions: dict[bytes, tuple[Any, Execution]] = {}
        self._goals_running = 0
        self._goals_lock = threading.Condition()
        self._last_scene_publish = 0.0
        self.cameras: CameraServer | None = None
        if settings.cameras and self.model.ncam > 0:
            self.cameras = CameraServer(session, self.model, self._camera_snapshot, settings.camera_rate)
        self._started = False
        self._stopped = False
        self._agent_watch: Any = None

    # -- public API ----------------------------------------------------------------------------------

    @property
    def sim_time(self) -> float:
        """Sim time of the last published step, s."""
        return self.simulation.sim_time

    @property
    def failure(self) -> BaseException | None:
        """The error that stopped the physics thread, if one did."""
        return self.simulation.failure

    @property
    def running(self) -> bool:
        """True between :meth:`start` and :meth:`stop` while the physics thread runs."""
        return self.simulation.running

    def start(self) -> None:
        """Serve everything in :meth:`interfaces` and start stepping."""
        if self._started:
            raise DriverError("the MuJoCo driver was already started")
        self._started = True
        try:
            self._serve()
            for name in self.settings.active_controllers:
                controller = self._controllers.get(name)
                if controller is not None:
                    controller.activate(self.data)
            # Before the physics thread owns the data: from then on only it may read it.
            self._publish_scene_state()
            self.simulation.start()
            if self.cameras is not None:
                self.cameras.start()
            self._watch_agents()
        except BaseException:
            self.stop()
            raise
        active = [c.name for c in self._controllers.values() if c.active]
        log.info(
            "MuJoCo driver ready: %s%s, keyframe %s, sim speed %s, %d joints, controllers active: %s",
            self.settings.model_path.name,
            f" (config {self.settings.config})" if self.settings.config else "",
            self.settings.keyframe or "(none)",
            format_sim_speed(self.settings.sim_speed),
            len(self._joint_names),
            ", ".join(active) or "none",
        )

    def stop(self) -> None:
        """Stop stepping, end running goals (aborted) and withdraw everything served."""
        if self._stopped:
            return
        self._stopped = True
        if self._agent_watch is not None:
            try:
                self._agent_watch.undeclare()
            except Exception:
                log.debug("agent watch already gone", exc_info=True)
        if self.cameras is not None:
            self.cameras.stop()
        self.simulation.stop()
        for controller in self._goal_controllers:
            controller.shutdown("the MuJoCo driver stopped")
        with self._goals_lock:
            self._goals_lock.wait_for(lambda: self._goals_running == 0, RESULT_GRACE)
        for node in reversed(self._nodes):
            node.close()
        self._nodes.clear()
        log.info("MuJoCo driver stopped at sim time %.3f s", self.simulation.sim_time)

    def interfaces(self) -> list[ServedInterface]:
        """The topics, services and actions this driver offers."""
        served = [
            ServedInterface("topic", names.CLOCK_TOPIC, names.CLOCK_TYPE, "simulation time"),
            ServedInterface(
                "topic", names.SCENE_STATE_TOPIC, names.SCENE_STATE_TYPE, "qpos and free bodies, for viewers"
            ),
            ServedInterface(
                "service", names.SET_STATE_SERVICE, names.SET_STATE_TYPE, "set joints or reset to a keyframe"
            ),
            ServedInterface(
                "service", names.BODIES_SERVICE, names.BODIES_TYPE, "free bodies and their poses"
            ),
            ServedInterface(
                "service", names.KEYFRAMES_SERVICE, names.KEYFRAMES_TYPE, "the model's keyframes"
            ),
            ServedInterface(
                "service", names.LIST_CONTROLLERS_SERVICE, names.LIST_CONTROLLERS_TYPE, "controllers"
            ),
            ServedInterface(
                "service",
                names.SWITCH_CONTROLLERS_SERVICE,
                names.SWITCH_CONTROLLERS_TYPE,
                "(de)activate controllers",
            ),
            ServedInterface(
                "service",
                names.SWITCH_CONTROLLERS_ALIAS,
                names.SWITCH_CONTROLLERS_TYPE,
                "(de)activate controllers",
            ),
        ]
        for name, controller in self._controllers.items():
            kind = controller.type_name
            if kind == cell.JOINT_STATE_BROADCASTER:
                served.append(
                    ServedInterface(
                        "topic", names.JOINT_STATES_TOPIC, names.JOINT_STATES_TYPE, "joint states"
                    )
                )
            elif kind in (cell.JOINT_TRAJECTORY_CONTROLLER, cell.ADMITTANCE_CONTROLLER):
                served.append(
                    ServedInterface(
                        "action",
                        names.follow_joint_trajectory_action(name),
                        names.FOLLOW_JOINT_TRAJECTORY_TYPE,
                        "track a timed joint trajectory"
                        + (
                            ", aborting on a force/torque threshold"
                            if kind == cell.ADMITTANCE_CONTROLLER
                            else ""
                        ),
                    )
                )
                if isinstance(controller, JointTrajectoryAdmittanceController):
                    served.append(
                        ServedInterface(
                            "action",
                            names.follow_joint_trajectory_action(name),
                            names.FOLLOW_JOINT_TRAJECTORY_WITH_ADMITTANCE_TYPE,
                            "track a timed joint trajectory with compliance and a force/torque threshold",
                        )
                    )
                    served.append(
                        ServedInterface(
                            "service",
                            names.admittance_zero_fts_service(name, controller.sensor.frame_id),
                            names.TRIGGER_TYPE,
                            "zero the force/torque sensor",
                        )
                    )
                served.append(
                    ServedInterface(
                        "topic",
                        names.joint_trajectory_topic(name),
                        names.JOINT_TRAJECTORY_TYPE,
                        "streamed trajectories, each replacing the last (subscribed; empty: stop)",
                    )
                )
            elif kind == cell.FORCE_TORQUE_SENSOR_BROADCASTER:
                served.append(
                    ServedInterface(
                        "topic", names.wrench_topic(name), names.WRENCH_TYPE, "the force/torque sensor"
                    )
                )
            elif kind == cell.VELOCITY_FORCE_CONTROLLER:
                served.append(
                    ServedInterface(
                        "topic",
                        names.velocity_force_command_topic(name),
                        names.VELOCITY_FORCE_COMMAND_TYPE,
                        "Cartesian velocity/force commands (subscribed)",
                    )
                )
                served.append(
                    ServedInterface(
                        "service",
                        names.zero_fts_service(name),
                        names.TRIGGER_TYPE,
                        "zero the force/torque sensor",
                    )
                )
            elif kind == cell.GRIPPER_ACTION_CONTROLLER:
                served.append(
                    ServedInterface(
                        "action",
                        names.gripper_command_action(name),
                        names.GRIPPER_COMMAND_TYPE,
                        "move the gripper",
                    )
                )
        if self.cameras is not None and self.cameras.unavailable is None:
            for spec in self.cameras.specs:
                for stream, type_name in names.CAMERA_STREAMS.items():
                    served.append(
                        ServedInterface(
                            "topic", names.camera_topic(spec.name, stream), type_name, f"{spec.name} {stream}"
                        )
                    )
        return served

    def __enter__(self) -> MujocoDriver:
        self.start()
        return self

    def __exit__(self, *_exc: object) -> None:
        self.stop()

    # -- construction ------------------------------------------------------------------------------

    def _build_controllers(self) -> dict[str, Controller]:
        """Make the controllers the settings name, each from its ros2_control type.

        A trajectory controller commands the joints its spec lists, or else every actuated joint but the
        gripper's. The F/T broadcaster, the admittance and the velocity-force controllers need the sensor
        (and the latter a control site) in the scene; without them they are left out with a warning.
        """
        settings = self.settings
        wanted = list(
            dict.fromkeys(
                n.lstrip("/") for n in [*settings.active_controllers, *settings.inactive_controllers]
            )
        )
        actuated = {j.name: j for j in self.index.actuated_joints}
        gripper_joint = actuated.get(settings.gripper_joint) if settings.gripper_joint else None
        if settings.gripper_joint and gripper_joint is None:
            log.warning(
                "the config's gripper joint %r has no actuator of its name in the scene "
                "(actuated joints: %s): no gripper controller",
                settings.gripper_joint,
                ", ".join(actuated) or "none",
            )
        default_arm = [j for j in actuated.values() if gripper_joint is None or j.name != gripper_joint.name]
        sensor = None
        if settings.force_torque_sensor and ForceTorqueSensor.present(
            self.model, settings.force_torque_sensor
        ):
            site = self.model.site(settings.force_torque_sensor)
            frame = self.model.body(int(site.bodyid[0])).name
            sensor = ForceTorqueSensor(self.model, settings.force_torque_sensor, frame)
        sites = {self.model.site(i).name for i in range(self.model.nsite)}
        has_control_site = bool(settings.control_site) and settings.control_site in sites
        arms: dict[tuple[str, ...], tuple[Any, ...]] = {}

        def arm_of(spec_joints: tuple[str, ...], controller: str) -> list[Any]:
            if not spec_joints:
                return default_arm
            unknown = [j for j in spec_joints if j not in actuated]
            if unknown:
                raise DriverError(
                    f"controller {controller!r} commands {', '.join(map(repr, unknown))}, which the scene "
                    f"{settings.model_path.name} does not actuate (an actuator named like the joint); "
                    f"actuated joints: {', '.join(actuated) or 'none'}"
                )
            return [actuated[j] for j in spec_joints]

        def tracking(arm: list[Any]) -> tuple[Any, ...]:
            key = tuple(j.name for j in arm)
            if key not in arms:
                gains = np.array([self.model.actuator_gainprm[j.actuator, 0] for j in arm])
                damping = np.array([-self.model.actuator_biasprm[j.actuator, 2] for j in arm])
                feedforward = np.divide(damping, gains, out=np.zeros_like(gains), where=gains > 0)
                arms[key] = (gains, feedforward, contact_reporter(self.model, list(key)))
            return arms[key]

        def trajectory_controller(
            name: str,
            arm: list[Any],
            kind: type[JointTrajectoryController] = JointTrajectoryController,
            **extra: Any,
        ) -> JointTrajectoryController:
            gains, feedforward, touching = tracking(arm)
            return kind(
                name,
                arm,
                feedforward,
                self.index.timestep,
                gains=gains if np.all(gains > 0) else None,
                inertia=self._effective_inertia([j.dof_address for j in arm]),
                touching=touching,
                **extra,
            )

        controllers: dict[str, Controller] = {}
        for name in wanted:
            spec = settings.controllers.get(name)
            kind = spec.type if spec is not None else cell.CONVENTIONAL_TYPES.get(name, "")
            joints = spec.joints if spec is not None else ()
            missing = ""
            if kind == cell.JOINT_STATE_BROADCASTER:
                controllers[name] = JointStateBroadcaster(name, self.index.joint_names)
            elif kind == cell.GRIPPER_ACTION_CONTROLLER:
                joint = actuated.get(joints[0]) if joints else gripper_joint
                if joint is None:
                    missing = f"an actuated gripper joint ({joints[0] if joints else 'robot.gripper.joint'})"
                else:
                    controllers[name] = GripperController(name, joint, self.model, settings.gripper)
            elif kind == cell.JOINT_TRAJECTORY_CONTROLLER:
                arm = arm_of(joints, name)
                if arm:
                    controllers[name] = trajectory_controller(name, arm)
                else:
                    missing = "actuated joints"
            elif kind == cell.FORCE_TORQUE_SENSOR_BROADCASTER:
                if sensor is None:
                    missing = (
                        f"the force/torque sensor site {settings.force_torque_sensor or '(none configured)'}"
                    )
                else:
                    controllers[name] = ForceTorqueSensorBroadcaster(name, sensor)
            elif kind == cell.ADMITTANCE_CONTROLLER:
                arm = arm_of(joints, name)
                if sensor is None or not arm:
                    missing = (
                        f"the force/torque sensor site {settings.force_torque_sensor or '(none configured)'}"
                    )
                else:
                    controllers[name] = trajectory_controller(
                        name,
                        arm,
                        JointTrajectoryAdmittanceController,
                        sensor=sensor,
                        model=self.model,
                        **_admittance_options(
                            name,
                            spec.parameters if spec is not None else {},
                            settings.control_site if has_control_site else "",
                            self.model,
                        ),
                    )
            elif kind == cell.VELOCITY_FORCE_CONTROLLER:
                arm = arm_of(joints, name)
                if sensor is None or not has_control_site or not arm:
                    missing = (
                        f"the force/torque sensor site {settings.force_torque_sensor or '(none configured)'} "
                        f"and the control site {settings.control_site or '(none configured)'}"
                    )
                else:
                    _, feedforward, _ = tracking(arm)
                    controllers[name] = VelocityForceController(
                        name, self.model, arm, feedforward, settings.control_site, sensor
                    )
            else:
                log.warning(
                    "controller %r (from the config) is not simulated: its type %s is not one the MuJoCo "
                    "driver offers (%s)",
                    name,
                    repr(kind) if kind else "is not given",
                    ", ".join(cell.SIMULATED_TYPES),
                )
                continue
            if missing:
                log.warning("controller %r (%s) is not simulated: the scene lacks %s", name, kind, missing)
        return controllers

    def _of_type(self, *kinds: str) -> list[tuple[str, Controller]]:
        """The controllers of the given ros2_control types, by name."""
        return [(n, c) for n, c in self._controllers.items() if c.type_name in kinds]

    def _effective_inertia(self, dofs: list[int]) -> Callable[[Any], np.ndarray]:
        """Each dof's effective inertia in the current state: the diagonal of MuJoCo's mass matrix."""
        import mujoco

        full = np.zeros((self.model.nv, self.model.nv))
        columns = np.asarray(dofs, dtype=int)

        def inertia(data: Any) -> np.ndarray:
            mujoco.mj_fullM(self.model, data, full)
            return np.diag(full)[columns].copy()

        return inertia

    def _serve(self) -> None:
        mujoco_node = self._node("mujoco")
        self._publishers["clock"] = mujoco_node.create_publisher(names.CLOCK_TYPE, names.CLOCK_TOPIC)
        self._publishers["scene"] = mujoco_node.create_publisher(
            names.SCENE_STATE_TYPE, names.SCENE_STATE_TOPIC, latched=True
        )
        mujoco_node.create_service(names.SET_STATE_TYPE, names.SET_STATE_SERVICE, self._on_set_state)
        mujoco_node.create_service(names.BODIES_TYPE, names.BODIES_SERVICE, self._on_bodies)
        mujoco_node.create_service(names.KEYFRAMES_TYPE, names.KEYFRAMES_SERVICE, self._on_keyframes)
        manager_node = self._node("controller_manager")
        manager_node.create_service(
            names.LIST_CONTROLLERS_TYPE, names.LIST_CONTROLLERS_SERVICE, self._on_list_controllers
        )
        for service in (names.SWITCH_CONTROLLERS_SERVICE, names.SWITCH_CONTROLLERS_ALIAS):
            manager_node.create_service(names.SWITCH_CONTROLLERS_TYPE, service, self._on_switch_controllers)
        for name, controller in self._of_type(cell.JOINT_STATE_BROADCASTER)[:1]:
            self._joint_state_broadcaster = controller
            self._publishers["joint_states"] = self._node(name).create_publisher(
                names.JOINT_STATES_TYPE, names.JOINT_STATES_TOPIC
            )
        for name, controller in self._of_type(cell.JOINT_TRAJECTORY_CONTROLLER, cell.ADMITTANCE_CONTROLLER):
            node = self._node(name)
            node.create_action_server(
                names.FOLLOW_JOINT_TRAJECTORY_TYPE,
                names.follow_joint_trajectory_action(name),
                functools.partial(self._execute_trajectory, controller=controller),
                cancel_callback=self._cancel_goal,
            )
            if isinstance(controller, JointTrajectoryAdmittanceController):
                node.create_action_server(
                    names.FOLLOW_JOINT_TRAJECTORY_WITH_ADMITTANCE_TYPE,
                    names.follow_joint_trajectory_action(name),
                    functools.partial(self._execute_trajectory, controller=controller),
                    cancel_callback=self._cancel_goal,
                )
                node.create_service(
                    names.TRIGGER_TYPE,
                    names.admittance_zero_fts_service(name, controller.sensor.frame_id),
                    functools.partial(self._zero_sensor, controller),
                )
            node.create_subscription(
                names.JOINT_TRAJECTORY_TYPE,
                names.joint_trajectory_topic(name),
                functools.partial(self._stream_trajectory, controller=controller),
            )
        for name, controller in self._of_type(cell.FORCE_TORQUE_SENSOR_BROADCASTER):
            assert isinstance(controller, ForceTorqueSensorBroadcaster)
            publisher = self._node(name).create_publisher(names.WRENCH_TYPE, names.wrench_topic(name))
            encoder = WrenchStampedEncoder(
                controller.sensor.frame_id, wrench_serializer(self.session.registry)
            )
            self._wrench_publishers.append((controller, publisher, encoder))
        for name, velocity_force in self._of_type(cell.VELOCITY_FORCE_CONTROLLER):
            assert isinstance(velocity_force, VelocityForceController)
            node = self._node(name)
            node.create_subscription(
                names.VELOCITY_FORCE_COMMAND_TYPE,
                names.velocity_force_command_topic(name),
                velocity_force.set_command,
            )
            node.create_service(
                names.TRIGGER_TYPE,
                names.zero_fts_service(name),
                functools.partial(self._zero_sensor, velocity_force),
            )
        for name, controller in self._of_type(cell.GRIPPER_ACTION_CONTROLLER):
            self._node(name).create_action_server(
                names.GRIPPER_COMMAND_TYPE,
                names.gripper_command_action(name),
                functools.partial(self._execute_gripper, controller=controller),
                cancel_callback=self._cancel_goal,
            )

    def _zero_sensor(
        self, controller: VelocityForceController | JointTrajectoryAdmittanceController, _request: Any
    ) -> dict[str, Any]:
        return {"success": True, "message": self.simulation.call(lambda: controller.zero_sensor(self.data))}

    def _camera_snapshot(self) -> SimState | None:
        try:
            return self.simulation.call(lambda: SimState.of(self.data), timeout=1.0)
        except DriverError:
            return None

    def _node(self, name: str) -> Node:
        node = Node(self.session, name)
        self._nodes.append(node)
        return node

    # -- the physics thread ------------------------------------------------------------------------

    def _before_step(self) -> None:
        data = self.data
        for controller in self._goal_controllers:
            controller.update(data)

    def _on_publish(self) -> None:
        data = self.data
        now = float(data.time)
        self._publishers["clock"].publish_raw(self._clock_encoder.encode(now))
        broadcaster = self._joint_state_broadcaster
        if broadcaster is not None and broadcaster.active:
            self._publishers["joint_states"].publish_raw(
                self._joint_state_encoder.encode(
                    now,
                    data.qpos[self._joint_qpos],
                    data.qvel[self._joint_dofs],
                    data.qfrc_actuator[self._joint_dofs],
                )
            )
        for sensor_broadcaster, publisher, encoder in self._wrench_publishers:
            if sensor_broadcaster.active:
                sec, nanosec = sensor_broadcaster.stamp(data)
                publisher.publish_raw(encoder.encode(sec, nanosec, sensor_broadcaster.sensor.read(data)))
        for controller in self._goal_controllers:
            controller.post_feedback(data)
        wall = time.perf_counter()
        if wall - self._last_scene_publish >= 1.0 / self.settings.scene_state_rate:
            self._publish_scene_state(wall)

    def _publish_scene_state(self, wall: float | None = None) -> None:
        self._last_scene_publish = time.perf_counter() if wall is None else wall
        data = self.data
        self._publishers["scene"].publish(
            {
                "stamp": _stamp(float(data.time)),
                "qpos": data.qpos.tolist(),
                "bodies": [_body(pose) for pose in free_body_poses(data, self.index)],
            }
        )

    def _set_state(
        self, keyframe: str, positions: dict[str, float], velocities: dict[str, float] | None
    ) -> str:
        check_joint_positions(self.index, positions)
        if keyframe:
            self.index.keyframe_id(keyframe)
        if not keyframe and not positions:
            raise DriverError(
                "nothing to set: give a keyframe (one of: "
                + (", ".join(self.index.keyframes) or "none")
                + ") and/or joint_state names and positions"
            )
        if keyframe:
            reset_to_keyframe(self.model, self.data, self.index, keyframe)
        moved = (
            apply_joint_state(self.model, self.data, self.index, positions, velocities) if positions else []
        )
        for controller in self._goal_controllers:
            controller.on_state_reset(self.data)
        self._publish_scene_state()
        parts = []
        if keyframe:
            parts.append(f"reset to keyframe {keyframe!r}")
        if moved:
            parts.append(f"set {len(moved)} joint{'s' if len(moved) != 1 else ''}")
        message = " and ".join(parts) + f" at sim time {float(self.data.time):.3f} s"
        log.info("simulation state %s", message)
        return message

    # -- services (transport threads) --------------------------------------------------------------

    def _on_list_controllers(self, _request: Any) -> dict[str, Any]:
        return {"controller": self.simulation.call(self.controller_manager.list_states)}

    def _on_switch_controllers(self, request: Any) -> dict[str, Any]:
        ok, message = self.simulation.call(
            lambda: self.controller_manager.switch(
                [str(n) for n in request.activate_controllers],
                [str(n) for n in request.deactivate_controllers],
                int(request.strictness),
                self.data,
            )
        )
        return {"ok": ok, "message": message}

    def _on_set_state(self, request: Any) -> dict[str, Any]:
        joint_state = request.joint_state
        joint_names = [str(n) for n in joint_state.name]
        positions = [float(v) for v in joint_state.position]
        velocities = [float(v) for v in joint_state.velocity]
        if len(positions) != len(joint_names):
            return {
                "success": False,
                "message": f"joint_state has {len(joint_names)} names but {len(positions)} positions",
            }
        if velocities and len(velocities) != len(joint_names):
            return {
                "success": False,
                "message": f"joint_state has {len(joint_names)} names but {len(velocities)} velocities",
            }
        keyframe = str(request.keyframe).strip()
        try:
            message = self.simulation.call(
                lambda: self._set_state(
                    keyframe,
                    dict(zip(joint_names, positions, strict=True)),
                    dict(zip(joint_names, velocities, strict=True)) if velocities else None,
                )
            )
        except DriverError as error:
            log.warning("set_state refused: %s", error)
            return {"success": False, "message": str(error)}
        return {"success": True, "message": message}

    def _on_bodies(self, _request: Any) -> dict[str, Any]:
        now, poses = self.simulation.call(
            lambda: (float(self.data.time), free_body_poses(self.data, self.index))
        )
        return {"stamp": _stamp(now), "bodies": [_body(pose) for pose in poses]}

    def _on_keyframes(self, _request: Any) -> dict[str, Any]:
        return {"names": list(self.index.keyframes), "initial": self.settings.keyframe or ""}

    # -- actions (goal threads) --------------------------------------------------------------------

    def _execute_trajectory(self, handle: ServerGoalHandle, controller: Any) -> None:
        assert isinstance(controller, JointTrajectoryController)
        limits = {j.name: j.limits for j in controller.joints if j.limits is not None}
        try:
            goal = parse_trajectory_goal(
                handle.goal, controller.joint_names, limits, self.settings.tolerances, self.index.timestep
            )
            admittance, threshold = _admittance_of(handle.goal)
        except GoalRejected as rejected:
            log.warning("%s: goal rejected: %s", controller.name, rejected.message)
            handle.abort({"error_code": rejected.code, "error_string": rejected.message})
            return

        def start(execution: Execution) -> None:
            if isinstance(controller, JointTrajectoryAdmittanceController):
                controller.start(execution, goal, self.data, admittance, threshold)
            else:
                controller.start(execution, goal, self.data)

        self._run_goal(
            handle,
            controller,
            start,
            {"error_code": INVALID_GOAL, "error_string": "the MuJoCo driver stopped"},
        )

    def _execute_gripper(self, handle: ServerGoalHandle, controller: Controller) -> None:
        assert isinstance(controller, GripperController)
        command = handle.goal.command
        position, effort = float(command.position), float(command.max_effort)
        self._run_goal(
            handle, controller, lambda execution: controller.start(execution, position, effort, self.data), {}
        )

    def _stream_trajectory(self, message: Any, controller: Any) -> None:
        """A trajectory on ``/<controller>/joint_trajectory``: replaces the running one (empty: stop)."""
        assert isinstance(controller, JointTrajectoryController)
        goal = None
        if message.points:
            limits = {j.name: j.limits for j in controller.joints if j.limits is not None}
            request = SimpleNamespace(
                trajectory=message,
                multi_dof_trajectory=SimpleNamespace(joint_names=[], points=[]),
                path_tolerance=[],
                goal_tolerance=[],
                goal_time_tolerance=SimpleNamespace(sec=0, nanosec=0),
            )
            try:
                goal = parse_trajectory_goal(
                    request, controller.joint_names, limits, self.settings.tolerances, self.index.timestep
                )
            except GoalRejected as rejected:
                log.warning("%s: trajectory on its topic rejected: %s", controller.name, rejected.message)
                return
        self.simulation.submit(lambda: controller.stream(goal, self.data))

    def _run_goal(
        self,
        handle: ServerGoalHandle,
        controller: Any,
        start: Callable[[Execution], None],
        stopped_result: dict[str, Any],
    ) -> None:
        execution = Execution(f"{controller.name} goal {handle.goal_uuid}")
        with self._goals_lock:
            self._goals_running += 1
            self._executions[handle.goal_id] = (controller, execution)
        try:
            self.simulation.submit(lambda: start(execution))
            cancel_sent = False
            while not execution.done.wait(FEEDBACK_PERIOD):
                if handle.is_cancel_requested and not cancel_sent:
                    # Normally the cancel callback already queued this; this covers a cancel that
                    # arrived before the goal was registered.
                    cancel_sent = self._queue_cancel(controller, execution)
                feedback = execution.take_feedback()
                if feedback is not None:
                    handle.publish_feedback(feedback)
                if not self.simulation.running:
                    execution.finish("aborted", stopped_result)
            outcome = execution.outcome
            assert outcome is not None
            if outcome.status == "succeeded":
                handle.succeed(outcome.result)
            elif outcome.status == "canceled":
                handle.canceled(outcome.result)
            else:
                handle.abort(outcome.result)
        finally:
            with self._goals_lock:
                self._executions.pop(handle.goal_id, None)
                self._goals_running -= 1
                self._goals_lock.notify_all()

    def _cancel_goal(self, handle: ServerGoalHandle) -> bool:
        with self._goals_lock:
            running = self._executions.get(handle.goal_id)
        if running is not None:
            self._queue_cancel(*running)
        return True

    def _watch_agents(self) -> None:
        """An agent that goes away (crashed, killed) can no longer cancel what it started: stop every
        running goal then, braking to a stop and holding position, until a new agent commands."""
        from kinema.transport.dispatch import channel, dispatch
        from kinema.transport.presence import AGENT, PRESENCE_PREFIX

        try:
            self._agent_watch = self.session.zenoh.liveliness().declare_subscriber(
                f"{PRESENCE_PREFIX}/{self.session.domain_id}/*/{AGENT}/**", channel(), history=False
            )
        except Exception:
            log.warning("cannot watch the agent's presence; its death will not stop running goals")
            return
        self.session._track_dispatcher(dispatch(self._agent_watch, self._on_agent_presence, "-agents"))

    def _on_agent_presence(self, sample: Any) -> None:
        import zenoh

        from kinema.transport.presence import parse_presence

        member = parse_presence(str(sample.key_expr))
        if member is None or sample.kind != zenoh.SampleKind.DELETE:
            return
        with self._goals_lock:
            running = list(self._executions.values())
        if running:
            log.warning(
                "%s went away with %d goal(s) running: stopping them and holding the robot still",
                member.describe(),
                len(running),
            )
        for controller, execution in running:
            self._queue_cancel(controller, execution)

    def _queue_cancel(self, controller: Any, execution: Execution) -> bool:
        try:
            self.simulation.submit(lambda: controller.cancel(execution, self.data))
        except DriverError:
            return False
        return True


def _body(pose: Any) -> dict[str, Any]:
    x, y, z = pose.position
    qx, qy, qz, qw = pose.orientation
    return {
        "name": pose.name,
        "pose": {"position": {"x": x, "y": y, "z": z}, "orientation": {"x": qx, "y": qy, "z": qz, "w": qw}},
    }
