"""ExecuteTrajectory: run a timed joint trajectory on the robot's trajectory controller."""

from __future__ import annotations

import time
from typing import Any

from kinema.behaviors import AsyncBehavior, FormerSpelling, PortInfo, input_port
from kinema.behaviors.work_runner import RUNNER
from kinema.config.cell import ADMITTANCE_CONTROLLER
from kinema.drivers.mujoco.names import LIST_CONTROLLERS_SERVICE, SWITCH_CONTROLLERS_SERVICE
from kinema.errors import KinemaError, ObjectiveError, TransportError

from ..controllers.switch_controller import (
    LIST_TYPE,
    STRICT,
    SWITCH_TYPE,
    conflicting_active,
    controller_states,
    switch_request,
)
from ..messages.conversions import duration, trajectory_from_message
from .joint_states import joint_state_monitor
from .planned_trajectory import publish_planned_trajectory

FOLLOW_JOINT_TRAJECTORY = "control_msgs/action/FollowJointTrajectory"
FOLLOW_JOINT_TRAJECTORY_WITH_ADMITTANCE = (
    "moveit_pro_controllers_msgs/action/FollowJointTrajectoryWithAdmittance"
)
ADMITTANCE_PARAMETERS = "moveit_pro_controllers_msgs/msg/AdmittanceParameters"
# Execution goes on without a switch when no controller manager is on the graph (another robot's
# driver) or it does not answer in time.
LIST_TIMEOUT = 2.0
# How long the controller's action server may be missing from the graph before the run fails: long
# enough to ride out a liveliness hiccup, short enough that a crashed driver fails the run within 1 s.
SERVER_LOST_AFTER = 0.3
_POLL = 0.01
# How often a running execution looks for its controller's action server on the graph.
SERVER_CHECK = 0.05
# After success, how long to wait for /joint_states to show the arm at the trajectory's end, and how many
# times the goal tolerance counts as there (the controller's default goal tolerance is 0.01 rad or m).
SETTLE_TIMEOUT = 2.0
SETTLE_FACTOR = 3.0
DEFAULT_GOAL_TOLERANCE = 0.01


class ExecuteTrajectory(AsyncBehavior):
    """Sends ``joint_trajectory_msg`` to a FollowJointTrajectory controller and waits until it is done.

    When the controller manager lists the controller (``/<controller>/follow_joint_trajectory``) as
    inactive, it is activated first, and the active controllers commanding the same joints are
    deactivated, as MoveIt's trajectory execution manager does with managed controllers. MoveIt Pro's
    objectives rely on it: lab_sim's "Pick All Bottles with AprilTags" retracts on the admittance
    controller right after "Pick from Pose" executed on the default one, with no SwitchController between.

    With ``admittance_parameters_msg`` or ``absolute_force_torque_threshold`` set, the trajectory travels
    with them in one FollowJointTrajectoryWithAdmittance goal to the joint trajectory admittance
    controller, which lets the arm give way to the wrench the wrist senses for this trajectory and aborts
    past the threshold (lab_sim's "Push Button With a Trajectory" and "Stationary Admittance").

    Halting the behavior (cancelling the objective) cancels the controller's goal, which stops the
    arm where it is. Fails with the controller's error when it rejects the trajectory (unknown joints,
    limits) or aborts it (tolerances), and fails within a second when the controller goes away.
    """

    subcategory = "Motion - Execute"
    former_spellings = (
        FormerSpelling(
            "ExecuteFollowJointTrajectory",
            ports={"execute_follow_joint_trajectory_action_name": "controller_action_name"},
        ),
    )

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "joint_trajectory_msg",
                None,
                "{joint_trajectory_msg}",
                "The trajectory to run (trajectory_msgs/JointTrajectory).",
            ),
            input_port(
                "controller_action_name",
                str,
                "/joint_trajectory_controller/follow_joint_trajectory",
                "The FollowJointTrajectory action of the controller.",
            ),
            input_port(
                "goal_duration_tolerance",
                float,
                -1.0,
                "Seconds the motion may overrun its duration (negative: the controller's default).",
            ),
            input_port(
                "goal_position_tolerance",
                list[float],
                "0.0",
                "Accepted final position error per joint: one value for all joints or one per joint "
                "(0: the controller's default).",
            ),
            input_port(
                "path_position_tolerance",
                list[float],
                "0.0",
                "Accepted tracking error along the way: one value for all joints or one per joint "
                "(0: the controller's default).",
            ),
            input_port(
                "execution_pipeline",
                str,
                "",
                "MoveIt Pro's execution pipeline (jtc, jtac); Kinema sends the trajectory to the "
                "controller of controller_action_name, activating it first when it is inactive.",
            ),
            input_port(
                "absolute_force_torque_threshold",
                list[float],
                "",
                "Abort when the wrench on the tool exceeds fx;fy;fz;tx;ty;tz (N, N m) along any axis of the "
                "wrist sensor's frame, counted from the sensor's zero (its reading less the tool's weight). "
                "Empty: the admittance controller's default (45 N, 10 N m, MoveIt Pro's). Given, the "
                "trajectory goes to the admittance controller as admittance_parameters_msg says.",
            ),
            input_port(
                "admittance_parameters_msg",
                None,
                "",
                "Compliance for this trajectory (moveit_pro_controllers_msgs/AdmittanceParameters, from "
                "SetAdmittanceParameters). Given, the trajectory and these parameters travel together in "
                "one FollowJointTrajectoryWithAdmittance goal to the admittance controller: the one "
                "controller_action_name names when it is one, else the config's controller of type "
                "joint_trajectory_admittance_controller/JointTrajectoryAdmittanceController (activated "
                "when inactive). The compliance lasts for this trajectory only.",
            ),
        ]

    def __init__(self, name: str, config: Any = None) -> None:
        super().__init__(name, config)
        self._handle: Any = None

    def trajectory_to_run(self) -> Any:
        """The trajectory_msgs/JointTrajectory to send (a subclass may make it from another port).

        Raises:
            KinemaError: the port does not give one (the run fails with the message).
        """
        return self.get_input("joint_trajectory_msg")

    def create_goal(self) -> dict[str, Any]:
        """The FollowJointTrajectory goal: the trajectory and the tolerances given on the ports."""
        message = self.trajectory_to_run()
        trajectory_from_message(
            message, "joint_trajectory_msg"
        )  # reject malformed input here, not in the driver
        names = [str(n) for n in message.joint_names]
        goal: dict[str, Any] = {"trajectory": message}
        for port, key in (
            ("path_position_tolerance", "path_tolerance"),
            ("goal_position_tolerance", "goal_tolerance"),
        ):
            tolerances = _per_joint(list(self.get_input(port)), names, port)
            if any(t > 0 for t in tolerances):
                goal[key] = [
                    {"name": n, "position": t} for n, t in zip(names, tolerances, strict=True) if t > 0
                ]
        time_tolerance = float(self.get_input("goal_duration_tolerance"))
        if time_tolerance >= 0:
            goal["goal_time_tolerance"] = duration(time_tolerance)
        return goal

    async def do_work(self) -> bool:
        outcome = await self._execute(trust_states=True)
        if outcome is None:  # the controller was not active after all: ask the controller manager
            controller_states(self.context).forget(LIST_CONTROLLERS_SERVICE)
            outcome = await self._execute(trust_states=False)
        return bool(outcome)

    async def _execute(self, *, trust_states: bool) -> bool | None:
        """Send the trajectory and wait for its end. None: the controller, taken as active from a listing
        under a second old (controller_states), turned the goal down as inactive (switched by someone
        else since, e.g. a reset of the simulation); the caller lists the controllers again."""
        import asyncio

        node = self.context.require_node(self.registration_id)
        name = str(self.get_input("controller_action_name"))
        action_type = FOLLOW_JOINT_TRAJECTORY
        try:
            goal = self.create_goal()
            admittance = self.admittance_fields()
            if admittance is not None:
                goal.update(admittance)
                action_type = FOLLOW_JOINT_TRAJECTORY_WITH_ADMITTANCE
                requested = name
                name = self.admittance_action(name, admittance.get("admittance_parameters"))
                if name != requested:
                    self.logger.publish_info(
                        f"{self.registration_id}: admittance ports set: executing on {name} (the admittance "
                        f"controller) instead of {requested}"
                    )
        except KinemaError as error:
            return self._fail(str(error))
        publish_planned_trajectory(self, goal["trajectory"])
        joint_state_monitor(self.context, "ExecuteTrajectory")  # listening before the arm moves
        refused, trusted = await self._activate(node, name, trust_states)
        if refused:
            return self._fail(refused)
        client = self.context.action_client(node, action_type, name)
        sending = RUNNER.run_function(lambda: client.send_goal(goal, timeout=5.0))
        try:
            handle = await asyncio.shield(asyncio.wrap_future(sending))
        except asyncio.CancelledError:
            sending.add_done_callback(_cancel_when_accepted)
            raise
        except TransportError as error:
            return self._fail(f"cannot send the trajectory to {name}: {error}")
        if not handle.accepted:
            if trusted:
                return None
            return self._fail(f"the controller {name} rejected the trajectory")
        self._handle = handle
        graph = node.session.graph_cache()
        missing_since: float | None = None
        # The result wakes this coroutine at once (the next behavior starts without waiting out a poll);
        # in between, every SERVER_CHECK the graph says whether the controller is still there.
        loop = asyncio.get_running_loop()
        finished: asyncio.Future[None] = loop.create_future()
        handle.add_done_callback(lambda _handle: loop.call_soon_threadsafe(_resolve, finished))
        try:
            while not handle.done():
                try:
                    await asyncio.wait_for(asyncio.shield(finished), SERVER_CHECK)
                except TimeoutError:
                    pass
                if handle.done():
                    break
                if graph.snapshot().action_server_ready(client.name):
                    missing_since = None
                    continue
                missing_since = missing_since or time.monotonic()
                if time.monotonic() - missing_since > SERVER_LOST_AFTER and not handle.done():
                    return self._fail(
                        f"lost the controller: {name} went away during execution (driver stopped or crashed)"
                    )
        except asyncio.CancelledError:
            if not handle.done():
                RUNNER.run_function(handle.cancel)
            raise
        finally:
            self._handle = None
        try:
            outcome = handle.result(0)
        except TransportError as error:
            return self._fail(f"the controller {name} failed: {error}")
        result = outcome.result
        if outcome.succeeded and int(result.error_code) == 0:
            if "admittance_parameters" not in goal:  # a compliant arm ends where the wrench put it
                await self._until_reported(goal)
            return True
        detail = str(result.error_string) or f"error code {int(result.error_code)}"
        if trusted and "inactive" in detail:
            return None
        return self._fail(f"the controller {name} ended the trajectory {outcome.status_name}: {detail}")

    async def _until_reported(self, goal: dict[str, Any]) -> None:
        """Wait until ``/joint_states`` shows the arm at the trajectory's last point.

        The controller's result can arrive before its last joint states do (on a loaded machine, or a
        simulation far faster than real time), and the next behavior plans from the latest state: a
        Cartesian move planned from where the arm was before this motion starts where the arm no longer
        is. Success means the controller saw the arm within its goal tolerance, so this waits, up to
        SETTLE_TIMEOUT, for the joint states to agree within a few times that tolerance, then goes on.
        """
        import asyncio

        import numpy as np

        trajectory = goal["trajectory"]
        if not trajectory.points:
            return
        names = [str(n) for n in trajectory.joint_names]
        target = np.array([float(p) for p in trajectory.points[-1].positions])
        tolerance = np.full(len(names), DEFAULT_GOAL_TOLERANCE)
        for entry in goal.get("goal_tolerance", []):
            tolerance[names.index(entry["name"])] = max(float(entry["position"]), DEFAULT_GOAL_TOLERANCE)
        monitor = joint_state_monitor(self.context, "ExecuteTrajectory")
        if not monitor.received:
            return  # this robot publishes no /joint_states
        deadline = time.monotonic() + SETTLE_TIMEOUT
        while True:
            try:
                gap = np.abs(monitor.positions(names, timeout=0.0) - target)
            except ObjectiveError:
                return  # /joint_states names other joints: nothing here to wait for
            if (gap <= SETTLE_FACTOR * tolerance).all():
                return
            if time.monotonic() > deadline:
                self.logger.publish_info(
                    f"ExecuteTrajectory: /joint_states still shows the arm {gap.max():.3g} from the "
                    f"trajectory's end {SETTLE_TIMEOUT:g} s after the controller reported success"
                )
                return
            await asyncio.sleep(_POLL)

    async def _activate(self, node: Any, action: str, trust_states: bool = True) -> tuple[str, bool]:
        """Activate the controller behind ``action`` when the controller manager has it inactive.

        Returns why that failed, or '' (also when there is no controller manager to ask), and whether the
        controller was taken as active from a recent listing without asking (``trust_states``).
        """
        import asyncio

        parts = action.strip("/").split("/")
        if len(parts) != 2 or parts[1] != "follow_joint_trajectory":
            return "", False
        controller = parts[0]
        known = controller_states(self.context)
        if trust_states and known.active(LIST_CONTROLLERS_SERVICE, [controller]):
            return "", True  # listed active within the last second (SwitchController just before, usually)
        lister = self.context.service_client(node, LIST_TYPE, LIST_CONTROLLERS_SERVICE)
        if not lister.service_is_ready():
            if trust_states:
                return "", False  # no controller manager on the graph (another robot's driver)
            # Asked again after the controller turned a goal down as inactive: a controller manager was
            # listed a moment ago, so wait for this client to see it on the graph.
            waiting = RUNNER.run_function(lambda: lister.wait_for_service(LIST_TIMEOUT))
            if not await asyncio.wrap_future(waiting):
                return "", False
        try:
            listing = await asyncio.wrap_future(lister.call_async({}, LIST_TIMEOUT))
        except TransportError:
            return "", False
        controllers = {str(c.name): c for c in listing.controller}
        known.remember(LIST_CONTROLLERS_SERVICE, controllers)
        if controller not in controllers or controllers[controller].state == "active":
            return "", False
        deactivate = conflicting_active(controllers, [controller])
        switcher = self.context.service_client(node, SWITCH_TYPE, SWITCH_CONTROLLERS_SERVICE)
        known.forget(LIST_CONTROLLERS_SERVICE)
        request = switch_request([controller], deactivate, STRICT, True, 5.0)
        try:
            response = await asyncio.wrap_future(switcher.call_async(request, 10.0))
        except TransportError as error:
            return f"{controller} is inactive and the controller manager cannot be reached: {error}", False
        if not response.ok:
            return f"{controller} is inactive and activating it was refused: {response.message}", False
        replaced = f" instead of {', '.join(deactivate)}" if deactivate else ""
        self.logger.publish_info(f"ExecuteTrajectory: activated {controller}{replaced} to execute")
        return "", False

    def do_halt(self) -> None:
        handle, self._handle = self._handle, None
        if handle is not None and not handle.done():
            RUNNER.run_function(handle.cancel)

    def _fail(self, reason: str) -> bool:
        self.logger.publish_failure(f"ExecuteTrajectory: {reason}")
        return False

    def admittance_fields(self) -> dict[str, Any] | None:
        """The admittance part of the goal (parameters, threshold), or None when no admittance port is set.

        Raises:
            ObjectiveError: a threshold of another count than six or not positive, or parameters that are
                not an AdmittanceParameters message; the message names the port.
        """
        threshold = self.get_input_or("absolute_force_torque_threshold", [])
        threshold = threshold if isinstance(threshold, list) else [threshold]
        parameters = self.get_input_or("admittance_parameters_msg", "")
        if not threshold and parameters in ("", None):
            return None
        if threshold and (len(threshold) != 6 or not all(float(v) > 0 for v in threshold)):
            raise ObjectiveError(
                f"port [absolute_force_torque_threshold] = {threshold}: give six positive values "
                "fx;fy;fz;tx;ty;tz (N, N m), or leave it empty for the controller's default"
            )
        fields: dict[str, Any] = {"absolute_force_torque_threshold": [float(v) for v in threshold]}
        if parameters not in ("", None):
            if getattr(parameters, "__msgtype__", "") != ADMITTANCE_PARAMETERS:
                raise ObjectiveError(
                    f"port [admittance_parameters_msg] holds {type(parameters).__name__}, not a "
                    f"{ADMITTANCE_PARAMETERS}; SetAdmittanceParameters writes one"
                )
            fields["admittance_parameters"] = parameters
        return fields

    def admittance_action(self, requested: str, parameters: Any = None) -> str:
        """The admittance controller's action for a goal with admittance: ``requested`` when it is one of
        the config's admittance controllers (or there is no config to ask), else the one the parameters'
        ``controller_name`` names, else the config's first.

        Raises:
            ObjectiveError: the config names no admittance controller, or the parameters name a controller
                that is not one.
        """
        cell = self.context.cell
        if cell is None:
            return requested
        actions = [
            f"/{spec.name}/follow_joint_trajectory"
            for spec in cell.controllers_of_type(ADMITTANCE_CONTROLLER)
        ]
        if "/" + requested.lstrip("/") in actions:
            return requested
        named = str(getattr(parameters, "controller_name", "") or "").strip("/")
        if named:
            if f"/{named}/follow_joint_trajectory" in actions:
                return f"/{named}/follow_joint_trajectory"
            raise ObjectiveError(
                f"port [admittance_parameters_msg] names controller_name {named!r}, which config "
                f"{cell.config!r} has not as an admittance controller; admittance controllers: "
                f"{', '.join(a.split('/')[1] for a in actions) or 'none'}"
            )
        if not actions:
            raise ObjectiveError(
                f"the admittance ports are set, but config {cell.config!r} has no controller of type "
                f"{ADMITTANCE_CONTROLLER} to run them (controllers: {', '.join(cell.controllers) or 'none'})"
            )
        return actions[0]


def _per_joint(values: list[float], names: list[str], port: str) -> list[float]:
    """One tolerance per joint from one value for all, or one per joint.

    Raises:
        ObjectiveError: another count of values, naming the port and the joints.
    """
    if len(values) == 1:
        return [float(values[0])] * len(names)
    if len(values) == len(names):
        return [float(v) for v in values]
    raise ObjectiveError(
        f"port [{port}] has {len(values)} values but the trajectory moves {len(names)} joints "
        f"({', '.join(names)}); give one value or one per joint"
    )


def _resolve(future: Any) -> None:
    if not future.done():
        future.set_result(None)


def _cancel_when_accepted(sending: Any) -> None:
    if sending.cancelled() or sending.exception() is not None:
        return
    handle = sending.result()
    if handle.accepted and not handle.done():
        RUNNER.run_function(handle.cancel)
