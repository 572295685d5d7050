"""ComputeLinkPoseForwardKinematics: where a link of the robot is for a given joint state."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.behaviors.cell_ports import cell_input_port
from kinema.errors import KinemaError

from ..messages.conversions import JOINT_STATE_TYPE, POSE_STAMPED_TYPE, pose_stamped_message
from ..messages.ports import fails_on_bad_input, message_input, message_output, read_message
from .frame_tree import current_frame_tree

PLANNING_SCENE_TYPE = "moveit_msgs/msg/PlanningScene"


class ComputeLinkPoseForwardKinematics(SyncBehavior):
    """Writes the pose of ``link_name`` in ``world`` with the robot at ``joint_state``.

    Joints that ``joint_state`` does not name keep their current value. ``planning_scene`` is accepted
    as in MoveIt Pro (its robot model is this runtime's, so it changes nothing here). Fails naming the
    link and the robot's links when the link does not exist.
    """

    subcategory = "Math - Poses"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("joint_state", JOINT_STATE_TYPE, "{joint_state}", "The robot's joint positions."),
            cell_input_port("link_name", str, "tool_frame", "The link whose pose to compute."),
            input_port(
                "planning_scene",
                None,
                "{planning_scene}",
                "The planning scene (moveit_msgs/PlanningScene, from GetCurrentPlanningScene); optional.",
            ),
            message_output("link_pose", POSE_STAMPED_TYPE, "{link_pose}", "The link's pose in world."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        state = read_message(self, "joint_state")
        link = str(self.get_input("link_name"))
        try:
            tree = current_frame_tree(self, joint_state=state)
            if self.context.robot_model is not None and link not in self.context.robot_model.link_names:
                from kinema.errors import did_you_mean

                raise KinemaError(
                    f"link_name {link!r} is not a link of the robot; "
                    f"{did_you_mean(link, self.context.robot_model.link_names)}"
                )
            pose = tree.world_T(link)
        except KinemaError as error:
            self.logger.publish_failure(f"ComputeLinkPoseForwardKinematics: {error}")
            return NodeStatus.FAILURE
        self.set_output("link_pose", pose_stamped_message("world", pose))
        return NodeStatus.SUCCESS
