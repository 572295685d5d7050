"""Robot states: CreateRobotState builds one, UnpackRobotStateMessage splits one.

MoveIt Pro's robot state on the blackboard is a ``moveit_studio_agent_msgs/RobotJointState`` (a joint
state and a multi-DOF joint state); a ``moveit_msgs/RobotState`` or a bare ``sensor_msgs/JointState`` is
accepted where one is read.
"""

from __future__ import annotations

from typing import Any

from kinema.behaviors import FormerSpelling, NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import did_you_mean

from .conversions import JOINT_STATE_TYPE, ROBOT_STATE_TYPE
from .ports import fails_on_bad_input, message_output, port_error, read_input


def as_robot_state(node: Any, port: str, value: Any) -> Any:
    """``value`` as a ``RobotJointState`` (given one, a ``moveit_msgs/RobotState`` or a JointState).

    Raises:
        PortValueError: none of these.
    """
    from kinema.transport import from_dict
    from kinema.transport.messages import to_dict

    ros_type = getattr(value, "__msgtype__", None)
    if ros_type == ROBOT_STATE_TYPE:
        return value
    if ros_type == "moveit_msgs/msg/RobotState":
        parts = to_dict(value)
        return from_dict(
            ROBOT_STATE_TYPE,
            {"joint_state": parts["joint_state"], "multi_dof_joint_state": parts["multi_dof_joint_state"]},
        )
    if ros_type == "sensor_msgs/msg/JointState":
        return from_dict(ROBOT_STATE_TYPE, {"joint_state": to_dict(value)})
    raise port_error(
        node,
        port,
        f"got {ros_type or type(value).__name__}",
        "expected a RobotJointState, moveit_msgs/RobotState or sensor_msgs/JointState (from "
        "CreateRobotState, RetrieveWaypoint, GetJointState or LoadRobotJointStateFromYaml)",
    )


class CreateRobotState(SyncBehavior):
    """Builds a robot state (``RobotJointState``) setting ``joint_names`` to ``positions``.

    It writes the state twice when asked: as a ``RobotJointState`` on ``robot_state`` and as a
    ``sensor_msgs/JointState`` on ``joint_state_msg`` (what GeneratePointToPointTrajectory reads), both
    with ``velocities`` when given. When the runtime has a robot model, every name must be one of its
    joints.
    """

    subcategory = "Messages"
    former_spellings = (FormerSpelling("CreateJointState"),)

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("joint_names", list[str], "", "Joint names (';'-separated)."),
            input_port("positions", list[float], "", "One position per joint (';'-separated)."),
            input_port(
                "velocities",
                list[float],
                "",
                "One velocity per joint (';'-separated, rad/s or m/s); unset or empty: the state has no "
                "velocities.",
            ),
            message_output(
                "robot_state",
                ROBOT_STATE_TYPE,
                "{joint_state_msg}",
                "The robot state. The default entry is the one SetMujocoState reads by default: MoveIt Pro's "
                "'Reset MuJoCo Robot' wires CreateRobotState to SetMujocoState by defaults only, and 'Load "
                "MuJoCo Robot State' writes {joint_state_msg} for the same SetMujocoState.",
            ),
            message_output(
                "joint_state_msg",
                JOINT_STATE_TYPE,
                description="The same state as a joint state, with its velocities (as MoveIt Pro's "
                "trajectory stitching objective feeds GeneratePointToPointTrajectory). No default: "
                "written only when the objective names an entry, because robot_state's default entry is "
                "{joint_state_msg} already.",
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        names = [name.strip() for name in read_input(self, "joint_names")]
        positions = list(read_input(self, "positions"))
        if not names:
            raise port_error(self, "joint_names", "is empty", "give joint names separated by ';'")
        if len(names) != len(positions):
            problem = f"= {positions}: {len(names)} joint names but {len(positions)} positions"
            raise port_error(self, "positions", problem, "give one position per joint")
        velocities = self._velocities(len(names))
        model = self.context.robot_model
        if model is not None:
            known = list(model.joint_names)
            unknown = [name for name in names if name not in known]
            if unknown:
                raise port_error(
                    self,
                    "joint_names",
                    f"names unknown joint {unknown[0]!r}",
                    did_you_mean(unknown[0], known),
                )
        from kinema.transport import from_dict

        fields = {"name": names, "position": [float(p) for p in positions], "velocity": velocities}
        self.set_output("robot_state", from_dict(ROBOT_STATE_TYPE, {"joint_state": fields}))
        if "joint_state_msg" in self.config.output_ports:
            self.set_output("joint_state_msg", from_dict(JOINT_STATE_TYPE, fields))
        return NodeStatus.SUCCESS

    def _velocities(self, count: int) -> list[float]:
        """The ``velocities`` port: none when unset or empty, else one number per joint."""
        if "velocities" not in self.config.input_ports:
            return []
        value = read_input(self, "velocities")
        try:
            velocities = [float(v) for v in value]
        except (TypeError, ValueError):
            raise port_error(self, "velocities", f"= {value!r} is not a list of numbers") from None
        if velocities and len(velocities) != count:
            problem = f"= {velocities}: {count} joint names but {len(velocities)} velocities"
            raise port_error(self, "velocities", problem, "give one velocity per joint, or none")
        return velocities


class UnpackRobotStateMessage(SyncBehavior):
    """Splits a robot state into its ``joint_state`` and ``multi_dof_joint_state``.

    Accepts a ``RobotJointState``, a ``moveit_msgs/RobotState`` or, as RetrieveWaypoint gives, a
    ``sensor_msgs/JointState``.
    """

    subcategory = "Messages"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "robot_state",
                None,
                "{robot_state}",
                "The robot state (RobotJointState or moveit_msgs/RobotState).",
            ),
            message_output("joint_state", "sensor_msgs/msg/JointState", "{joint_state}", "Its joint state."),
            message_output(
                "multi_dof_joint_state",
                "sensor_msgs/msg/MultiDOFJointState",
                "{multi_dof_joint_state}",
                "Its multi-DOF joint state.",
            ),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        state = as_robot_state(self, "robot_state", read_input(self, "robot_state"))
        self.set_output("joint_state", state.joint_state)
        self.set_output("multi_dof_joint_state", state.multi_dof_joint_state)
        return NodeStatus.SUCCESS
