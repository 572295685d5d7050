"""InitializeMTCTask and the SetupMTC* behaviors: create a task and append stages to it.

Each SetupMTC* behavior appends one stage to the task on its ``task`` port and succeeds; nothing is
planned until PlanMTCTask. Bad values (an axis of zeros, a scale factor outside (0, 1], a pose that is
not a PoseStamped) fail the behavior naming the port.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from kinema.behaviors import (
    FormerSpelling,
    NodeStatus,
    PortInfo,
    SyncBehavior,
    bidirectional_port,
    input_port,
    output_port,
)
from kinema.behaviors.cell_ports import cell_input_port
from kinema.errors import KinemaError

from ..messages.conversions import joint_positions, pose_matrix
from ..messages.ports import message_input, message_vector_input, speed_scale_ports
from .mtc_task import CurrentStateMarker, MtcTask, stage_name, task_input

SUBCATEGORY = "Motion - Task Planning"


@dataclass(frozen=True)
class MotionPorts:
    """The ports a stage's motion settings come from, declared once: :meth:`ports` lists them and
    :meth:`read` builds the :class:`~kinema.motion.task_stages.MotionSettings` from the same names.

    MoveIt Pro names them differently per behavior (``velocity_scale_factor`` on the planning stages,
    ``velocity_scale`` on SetupMTCMoveAlongFrameAxis), and not every stage has every one.

    Attributes:
        velocity: the velocity scale port, or None (full speed).
        acceleration: the acceleration scale port, or None.
        planning: the ports of a planned motion: ``link_padding``, ``trajectory_sampling_rate`` and
            ``max_iterations``; without them the padding is ``padding`` and the sampling period 10 ms.
        seed: a ``seed`` port (the IK restarts' random seed).
        padding: the link padding (m) of a stage without a ``link_padding`` port.
    """

    velocity: str | None = "velocity_scale_factor"
    acceleration: str | None = "acceleration_scale_factor"
    planning: bool = True
    seed: bool = False
    padding: float = 0.01

    def ports(self) -> list[PortInfo]:
        ports = [
            cell_input_port("planning_group_name", str, "planning_group", "The planning group that moves.")
        ]
        ports += speed_scale_ports(self.velocity, self.acceleration)
        if self.planning:
            ports += [
                input_port(
                    "link_padding", float, 0.01, "Clearance (m) kept between the robot and the scene."
                ),
                input_port(
                    "trajectory_sampling_rate", int, 100, "Points per second of the planned trajectory."
                ),
                input_port(
                    "max_iterations",
                    int,
                    5000,
                    "Samples the collision-free search (a seeded RRT-Connect, like MoveIt Pro's RRT) draws "
                    "before the stage fails; the search is also bounded by 1 s.",
                ),
            ]
        if self.seed:
            ports.append(
                input_port(
                    "seed",
                    int,
                    0,
                    "Seed of the IK restarts and of the collision-free search: the same task, scene and "
                    "seed give the same solution, in any process.",
                )
            )
        return ports

    def read(self, behavior: Any) -> Any:
        """The motion settings ``behavior``'s ports ask for.

        Raises:
            KinemaError: a value out of range (a scale factor outside (0, 1], a rate that is not positive).
        """
        from kinema.motion.task_stages import MotionSettings

        settings: dict[str, Any] = {"group": str(behavior.get_input("planning_group_name"))}
        if self.velocity:
            settings["velocity_scale"] = float(behavior.get_input(self.velocity))
        if self.acceleration:
            settings["acceleration_scale"] = float(behavior.get_input(self.acceleration))
        settings["link_padding"] = (
            float(behavior.get_input("link_padding")) if self.planning else self.padding
        )
        if self.planning:
            rate = float(behavior.get_input("trajectory_sampling_rate"))
            if not rate > 0:
                raise KinemaError(
                    f"trajectory_sampling_rate must be positive (points per second), got {rate}"
                )
            settings["sample_period"] = 1.0 / rate
            settings["max_iterations"] = int(behavior.get_input("max_iterations"))
        if self.seed:
            settings["seed"] = int(behavior.get_input("seed"))
        return MotionSettings(**settings)


class _SetupStage(SyncBehavior):
    """Append the stage :meth:`stage` builds; fail naming the reason when it cannot.

    A subclass declares its own ports in :meth:`stage_ports` and, when its stage moves the robot, where
    its motion settings come from in :attr:`MOTION` (read with ``self.motion()``); the ``task`` port and
    the motion ports are added here.
    """

    subcategory = SUBCATEGORY
    MOTION: MotionPorts | None = None

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        motion = cls.MOTION.ports() if cls.MOTION is not None else []
        return [
            bidirectional_port("task", None, "{mtc_task}", "The MTC task to add the stage to."),
            *cls.stage_ports(),
            *motion,
        ]

    @classmethod
    def stage_ports(cls) -> list[PortInfo]:
        """The ports of this stage besides ``task`` and the motion ports."""
        return []

    def motion(self) -> Any:
        """The stage's motion settings, read from the ports :attr:`MOTION` declares."""
        assert self.MOTION is not None, f"{type(self).__name__} declares no motion ports"
        return self.MOTION.read(self)

    def stage(self, task: MtcTask) -> Any:
        raise NotImplementedError

    def tick(self) -> NodeStatus:
        try:
            task = task_input(self)
            stage = self.stage(task)
        except KinemaError as error:
            self.logger.publish_failure(f"{self.registration_id}: {error}")
            return NodeStatus.FAILURE
        task.stages.append(stage)
        self.set_output("task", task)
        return NodeStatus.SUCCESS


class InitializeMTCTask(SyncBehavior):
    """Creates an empty MTC task on ``task``; SetupMTC* behaviors add its stages, PlanMTCTask plans it."""

    subcategory = SUBCATEGORY
    former_spellings = (
        FormerSpelling(
            dropped={
                "controller_names": "the controllers are chosen where the solution executes (the "
                "controller_names of 'Execute MTC Solution')"
            }
        ),
    )

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            output_port("task", None, "{mtc_task}", "The new task."),
            input_port("task_id", str, "", "A name for the task (shown while it is planned)."),
            input_port("timeout", float, -1.0, "Seconds planning may take in all; -1: no limit."),
        ]

    def tick(self) -> NodeStatus:
        self.set_output("task", MtcTask(str(self.get_input("task_id")), float(self.get_input("timeout"))))
        return NodeStatus.SUCCESS


class SetupMTCCurrentState(_SetupStage):
    """Adds the robot's state when the task is planned as the task's start."""

    def stage(self, task: MtcTask) -> Any:
        return CurrentStateMarker()


class SetupMTCConnectWithProRRT(_SetupStage):
    """Adds a connect stage: a collision-free joint-space motion between the stages around it."""

    MOTION = MotionPorts(seed=True)

    def stage(self, task: MtcTask) -> Any:
        from kinema.motion.task_stages import Connect

        return Connect(self.motion(), name=stage_name(task, "connect"))


class SetupMTCPlanToPose(_SetupStage):
    """Adds a stage that moves ``ik_frame`` to ``target_pose`` (IK from several seeds, then a free motion)."""

    MOTION = MotionPorts()

    @classmethod
    def stage_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "target_pose", "geometry_msgs/msg/PoseStamped", "{target_pose}", "Where ik_frame goes."
            ),
            cell_input_port("ik_frame", str, "tool_frame", "The robot frame placed at the target pose."),
            input_port(
                "monitored_stage",
                str,
                "current state",
                "The stage whose state frames are resolved at (Kinema: the state before this stage).",
            ),
            input_port(
                "orientation_constraint",
                None,
                "[]",
                "Links to keep turned at most angle_tolerance (rad) from their orientation where the stage "
                "starts, target included: '[{link_name: <tool link>, angle_tolerance: 0.2}]'; '[]': none. "
                "Kinema checks the free motion and, when it turns a link too far, moves the ik_frame in a "
                "straight line instead; the stage fails naming the link and angle when neither keeps it.",
            ),
        ]

    def stage(self, task: MtcTask) -> Any:
        from kinema.motion.task_stages import PlanToPose

        target = pose_matrix(self.get_input("target_pose"), "target_pose")
        return PlanToPose(
            target,
            str(self.get_input("ik_frame")),
            self.motion(),
            name=stage_name(task, "plan to pose"),
            orientation_constraints=orientation_constraints(self.get_input("orientation_constraint")),
        )


def orientation_constraints(value: Any) -> list[Any]:
    """The ``orientation_constraint`` port's constraints: a list of ``{link_name, angle_tolerance}``,
    written as YAML (``[{link_name: <tool link>, angle_tolerance: 0.2}]``) or passed on the blackboard.

    Raises:
        KinemaError: not such a list, or an entry without a link name or with a bad tolerance.
    """
    import yaml

    from kinema.motion.task_stages import OrientationConstraint

    shape = "a list like [{link_name: <tool link>, angle_tolerance: 0.2}]"
    if value is None or (isinstance(value, str) and not value.strip()):
        return []
    if isinstance(value, str):
        try:
            value = yaml.safe_load(value)
        except yaml.YAMLError as error:
            raise KinemaError(f"port [orientation_constraint] is not YAML ({error}); give {shape}") from None
    if isinstance(value, dict):
        value = [value]
    if not isinstance(value, list | tuple):
        raise KinemaError(f"port [orientation_constraint] must be {shape}, got {value!r}")
    constraints = []
    for k, item in enumerate(value):
        if not isinstance(item, dict) or not str(item.get("link_name") or "").strip():
            raise KinemaError(f"port [orientation_constraint] entry {k} names no link_name; give {shape}")
        try:
            tolerance = float(item.get("angle_tolerance", 0.0))
        except (TypeError, ValueError):
            raise KinemaError(
                f"port [orientation_constraint] entry {k}: angle_tolerance must be a number (rad), got "
                f"{item.get('angle_tolerance')!r}"
            ) from None
        constraints.append(OrientationConstraint(str(item["link_name"]).strip(), tolerance))
    return constraints


class SetupMTCPlanToRobotState(_SetupStage):
    """Adds a stage that moves the planning group to ``joint_state`` (a collision-free motion).

    The straight joint-space motion is tried first, and planned around obstacles (keeping ``link_padding``,
    drawing at most ``max_iterations`` samples from ``seed``) only when it collides; the motion is timed
    under the scaled limits and sampled ``trajectory_sampling_rate`` times a second. It is also what
    MoveIt Pro's former SetupMTCInterpolateToJointState reads as.
    """

    former_spellings = (
        FormerSpelling("SetupMTCInterpolateToJointState"),
        FormerSpelling("SetupMTCPlanToJointState"),
    )
    MOTION = MotionPorts(seed=True)

    @classmethod
    def stage_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "joint_state",
                None,
                "{target_joint_state}",
                "The goal (sensor_msgs/JointState, e.g. from RetrieveWaypoint).",
            ),
        ]

    def stage(self, task: MtcTask) -> Any:
        from kinema.motion.task_stages import PlanToJointState

        goal = joint_positions(self.get_input("joint_state"), "joint_state")
        if not goal:
            raise KinemaError("port [joint_state] names no joint")
        return PlanToJointState(goal, self.motion(), name=stage_name(task, "plan to joint state"))


class SetupMTCCartesianMoveToRobotState(_SetupStage):
    """Adds a stage that moves the tip of the planning group in a straight line to where ``joint_state``
    puts it, ending at ``joint_state`` (a retreat along the way the robot came, as MoveIt Pro's "Retreat To
    Initial Pose" does after a push).

    The tip is the group's tip link (its SRDF chain's end); joints of ``joint_state`` outside the group
    (the gripper of a saved robot state) are left where they are. Like SetupMTCMoveAlongFrameAxis it keeps
    no link padding. Planning fails when the straight line is blocked or unreachable, or when it reaches
    the tip's goal pose in another joint configuration than ``joint_state`` (then plan to it instead).
    """

    MOTION = MotionPorts(planning=False, padding=0.0)

    @classmethod
    def stage_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "joint_state",
                None,
                "{target_joint_state}",
                "Where the motion ends (sensor_msgs/JointState or moveit_msgs/RobotState, e.g. a saved "
                "current state).",
            ),
        ]

    def stage(self, task: MtcTask) -> Any:
        from kinema.motion.task_stages import CartesianMoveToJointState

        goal = joint_positions(self.get_input("joint_state"), "joint_state")
        if not goal:
            raise KinemaError("port [joint_state] names no joint")
        return CartesianMoveToJointState(
            goal, self.motion(), name=stage_name(task, "cartesian move to joint state")
        )


class SetupMTCMoveAlongFrameAxis(_SetupStage):
    """Adds a straight-line motion of ``hand_frame`` along an axis of ``axis_frame``.

    It moves ``max_distance`` when it can and fails when less than ``min_distance`` is reachable. Before
    a pose IK stage (an approach) it is planned backwards, so it ends at the pose.
    """

    MOTION = MotionPorts("velocity_scale", "acceleration_scale", planning=False, padding=0.0)

    @classmethod
    def stage_ports(cls) -> list[PortInfo]:
        return [
            cell_input_port("axis_frame", str, "tool_frame", "The frame the axis is given in."),
            input_port("axis_x", float, 0.0, "Axis x component."),
            input_port("axis_y", float, 0.0, "Axis y component."),
            input_port("axis_z", float, 1.0, "Axis z component."),
            cell_input_port("hand_frame", str, "tool_frame", "The robot frame that moves along the axis."),
            input_port("min_distance", float, 0.1, "Least distance (m) the motion must cover."),
            input_port("max_distance", float, 0.1, "Distance (m) to cover when reachable."),
            input_port(
                "ignore_environment_collisions",
                bool,
                False,
                "Plan through the planning scene's objects (the robot still must not hit itself).",
            ),
        ]

    def stage(self, task: MtcTask) -> Any:
        from kinema.motion.task_stages import MoveAlongFrameAxis

        return MoveAlongFrameAxis(
            (
                float(self.get_input("axis_x")),
                float(self.get_input("axis_y")),
                float(self.get_input("axis_z")),
            ),
            str(self.get_input("axis_frame")),
            str(self.get_input("hand_frame")),
            float(self.get_input("min_distance")),
            float(self.get_input("max_distance")),
            self.motion(),
            bool(self.get_input("ignore_environment_collisions")),
            name=stage_name(task, "move along frame axis"),
        )


class SetupMTCBatchPoseIK(_SetupStage):
    """Adds a stage that solves IK for each of ``target_poses`` and keeps the solutions closest to the
    state before (up to ``max_ik_solutions``); the stages around it plan to or from the closest that works.
    """

    # MoveIt Pro's old one-stage pick (approach, close the gripper, lift, set by LoadObjectiveParameters)
    # became a few stages and behaviors, this one among them; Kinema plans no gripper motion inside a
    # task, so the old stage is refused with how to write it today rather than half done.
    former_spellings = (
        FormerSpelling(
            "SetupMTCPickObject",
            refused="it planned the approach, closed the gripper and lifted in one MTC stage, and Kinema's "
            "task planner moves no gripper; write it as MoveIt Pro's lab_sim 'Pick from Pose' does today: "
            "SetupMTCConnectWithProRRT, SetupMTCMoveAlongFrameAxis (the approach), SetupMTCBatchPoseIK "
            "(the grasp pose), PlanMTCTask and 'Execute MTC Solution', then 'Close Gripper' and a "
            "PlanCartesianPath + ExecuteTrajectory to lift",
        ),
    )

    @classmethod
    def stage_ports(cls) -> list[PortInfo]:
        return [
            message_vector_input(
                "target_poses", "geometry_msgs/msg/PoseStamped", "{target_poses}", "Candidate poses."
            ),
            cell_input_port("ik_group", str, "planning_group", "The planning group IK moves."),
            cell_input_port("end_effector_link", str, "tool_frame", "The robot frame placed at a pose."),
            input_port(
                "end_effector_group",
                str,
                "moveit_ee",
                "MoveIt's end-effector group (Kinema checks the whole robot for collisions).",
            ),
            input_port("max_ik_solutions", int, 4, "How many solutions later stages may try."),
            input_port(
                "ik_timeout_s",
                float,
                0.01,
                "MoveIt Pro's IK timeout per pose; Kinema bounds IK by seeds (20 per pose) instead.",
            ),
            input_port(
                "monitored_stage",
                str,
                "current state",
                "The stage whose state IK starts from (Kinema: the state before this stage).",
            ),
        ]

    def stage(self, task: MtcTask) -> Any:
        from kinema.motion.task_stages import BatchPoseIK

        value = self.get_input("target_poses")
        items = list(value) if isinstance(value, list | tuple) else [value]
        if not items:
            raise KinemaError("port [target_poses] is an empty vector")
        targets = [pose_matrix(item, f"target_poses[{i}]") for i, item in enumerate(items)]
        return BatchPoseIK(
            targets,
            str(self.get_input("end_effector_link")),
            str(self.get_input("ik_group")),
            int(self.get_input("max_ik_solutions")),
            name=stage_name(task, "batch pose IK"),
        )


class SetupMTCFromSolution(_SetupStage):
    """Adds an earlier ``solution``'s motions; the task goes on from where it ended.

    A task that starts with it replays the solution; when the robot is no longer where the solution
    starts, PlanMTCTask plans a collision-free move there first (Kinema's rule; MoveIt Pro's is not
    public), instead of a jump.
    """

    @classmethod
    def stage_ports(cls) -> list[PortInfo]:
        return [input_port("solution", None, "{solution}", "A solution PlanMTCTask planned.")]

    def stage(self, task: MtcTask) -> Any:
        from kinema.motion.task import TaskSolution
        from kinema.motion.task_stages import FromSolution

        solution = self.get_input_or("solution", None)
        if not isinstance(solution, TaskSolution):
            got = "nothing" if solution is None else type(solution).__name__
            raise KinemaError(f"port [solution] needs a solution PlanMTCTask planned, got {got}")
        return FromSolution(solution, name=stage_name(task, "from solution"))
