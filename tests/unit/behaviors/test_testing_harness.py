"""``kinema.testing.run_objective`` runs an objective as the runtime runs one on its own: the ports it
declares start from their defaults, and overrides replace them (a behavior author's test found the
defaults missing: "unable to find the key [a] remapped to [x]")."""

from __future__ import annotations

import pytest

from kinema.bt import NodeStatus
from kinema.errors import ObjectiveError
from kinema.testing import run_objective

OBJECTIVE = """<root BTCPP_format="4" main_tree_to_execute="Blend">
  <BehaviorTree ID="Blend">
    <Sequence>
      <Sleep msec="{pause}" />
      <SetBlackboard value="{label}" output_key="shown" />
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <SubTree ID="Blend">
      <input_port name="pause" default="1" />
      <input_port name="label" default="sum" />
    </SubTree>
  </TreeNodesModel>
</root>
"""


def test_declared_defaults_are_read_and_overrides_replace_them() -> None:
    run = run_objective(OBJECTIVE)
    assert run.status is NodeStatus.SUCCESS, run.toasts
    assert run.blackboard["pause"] == 1 and run.blackboard["shown"] == "sum"
    run = run_objective(OBJECTIVE, overrides={"pause": "2", "label": "total"})
    assert run.status is NodeStatus.SUCCESS, run.toasts
    assert run.blackboard["pause"] == 2 and run.blackboard["shown"] == "total"


def test_an_override_no_port_reads_is_refused_with_the_parameters() -> None:
    with pytest.raises(ObjectiveError, match=r"reads the blackboard key 'paus'; did you mean 'pause'\?"):
        run_objective(OBJECTIVE, overrides={"paus": "3"})


def test_a_message_port_type_builds_the_message_a_test_hands_tick_behavior() -> None:
    """A behavior author's test needs a JointState for a message port: calling the port type builds one
    (unset fields at their ROS defaults), and it is the port's type."""
    from typing import Any

    from kinema.behaviors import SyncBehavior, input_port, message_type, output_port
    from kinema.errors import TransportError
    from kinema.testing import tick_behavior

    joint_state = message_type("sensor_msgs/msg/JointState")

    class FirstJoint(SyncBehavior):
        @classmethod
        def provided_ports(cls) -> list[Any]:
            return [input_port("state", joint_state, "{state}"), output_port("value", float, "{value}")]

        def tick(self) -> NodeStatus:
            state = self.get_required_inputs("state")[0]
            self.set_output("value", float(state.position[0]))
            return NodeStatus.SUCCESS

    state = joint_state(name=["elbow_joint"], position=[0.5])
    assert isinstance(state, joint_state) and state.header.frame_id == "" and list(state.velocity) == []
    result = tick_behavior(FirstJoint, {"state": state})
    assert result.status is NodeStatus.SUCCESS and result.outputs["value"] == 0.5
    with pytest.raises(TransportError, match="did you mean 'name'"):
        joint_state(nam=["elbow_joint"])
    # An orientation left out is the identity rotation, as rclpy and rclcpp make it.
    pose = message_type("geometry_msgs/msg/PoseStamped")(pose={"position": {"x": 0.1}})
    assert (pose.pose.orientation.w, pose.pose.position.x) == (1.0, 0.1)
