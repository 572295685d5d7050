"""The vectors and messages families: what an objective sees, and how bad input fails (never raises)."""

from __future__ import annotations

from typing import Any

import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import run_objective, tick_behavior


def _xml(body: str) -> str:
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main"><Sequence>'
        f"{body}</Sequence></BehaviorTree></root>"
    )


POSES = """
<Action ID="ResetPoseStampedVector" vector="{poses}"/>
<Action ID="CreatePoseStamped" position_xyz="1;0;0" pose_stamped="{a}"/>
<Action ID="CreatePoseStamped" position_xyz="2;0;0" pose_stamped="{b}"/>
<Action ID="CreatePoseStamped" position_xyz="3;0;0" pose_stamped="{c}"/>
<Action ID="PushBackVector" input_vector="{poses}" element="{a}" output_vector="{poses}"/>
<Action ID="PushBackVector" input_vector="{poses}" element="{c}" output_vector="{poses}"/>
<Action ID="InsertInVector" input_vector="{poses}" element="{b}" index="1" output_vector="{poses}"/>
"""


def _x(poses: list[Any]) -> list[float]:
    return [pose.pose.position.x for pose in poses]


def test_a_pose_vector_is_built_edited_and_read(registry: Any, context: BehaviorContext) -> None:
    result = run_objective(
        _xml(
            POSES
            + """
            <Action ID="GetSizeOfVector" vector_in="{poses}" vector_size="{size}"/>
            <Action ID="GetElementOfVector" vector_in="{poses}" index="2" element="{last}"/>
            <Action ID="ReplaceInVector" input_vector="{poses}" element="{a}" index="2"
                    output_vector="{edited}"/>
            <Action ID="RemoveFromVector" input_vector="{edited}" index="0" output_vector="{edited}"/>
            """
        ),
        registry=registry,
        context=context,
    )
    assert result.status == NodeStatus.SUCCESS, result.toasts
    board = result.blackboard
    assert _x(board["poses"]) == [1.0, 2.0, 3.0]
    assert board["size"] == 3
    assert board["last"].pose.position.x == 3.0
    assert _x(board["edited"]) == [2.0, 1.0]


def test_for_each_visits_every_element_in_order_with_its_index(
    registry: Any, context: BehaviorContext
) -> None:
    result = run_objective(
        _xml(
            POSES
            + """
            <Action ID="ResetVector" vector="{seen}"/>
            <Decorator ID="ForEach" vector_in="{poses}" out="{pose}" index="{i}">
              <Sequence>
                <Action ID="UnpackPoseStampedMessage" pose_stamped="{pose}" pose="{p}" header="{h}"/>
                <Action ID="UnpackPoseMessage" pose="{p}" position="{point}" orientation="{q}"/>
                <Action ID="UnpackPointMessage" point="{point}" x="{x}" y="{y}" z="{z}"/>
                <Action ID="PushBackVector" input_vector="{seen}" element="{x}" output_vector="{seen}"/>
              </Sequence>
            </Decorator>
            """
        ),
        registry=registry,
        context=context,
    )
    assert result.status == NodeStatus.SUCCESS, result.toasts
    assert result.blackboard["seen"] == [1.0, 2.0, 3.0]
    assert result.blackboard["i"] == 2


def test_for_each_until_success_stops_at_the_first_success(registry: Any, context: BehaviorContext) -> None:
    result = run_objective(
        _xml(
            POSES
            + """
            <Decorator ID="ForEachUntilSuccess" vector_in="{poses}" out="{item}" index="{i}">
              <Sequence>
                <Action ID="UnpackPoseStampedMessage" pose_stamped="{item}" pose="{p}"/>
                <Action ID="UnpackPoseMessage" pose="{p}" position="{point}"/>
                <Action ID="UnpackPointMessage" point="{point}"/>
                <Script code="found := x"/>
                <ScriptCondition code="x &gt; 1.5"/>
              </Sequence>
            </Decorator>
            """
        ),
        registry=registry,
        context=context,
    )
    assert result.status == NodeStatus.SUCCESS, result.toasts
    assert result.blackboard["i"] == 1 and result.blackboard["found"] == 2.0


def test_for_each_until_success_fails_when_nothing_succeeds_and_for_each_succeeds_on_empty(
    registry: Any, context: BehaviorContext
) -> None:
    body = """
        <Action ID="ResetVector" vector="{empty}"/>
        <Decorator ID="ForEach" vector_in="{empty}" out="{e}" index="{i}"><AlwaysFailure/></Decorator>
        <Decorator ID="ForEachUntilSuccess" vector_in="{empty}" out="{e}" index="{j}">
          <AlwaysSuccess/>
        </Decorator>
    """
    result = run_objective(_xml(body), registry=registry, context=context)
    assert result.status == NodeStatus.FAILURE
    assert "i" not in result.blackboard or result.blackboard["i"] is None


@pytest.mark.parametrize(
    ("behavior_id", "inputs", "port", "expected"),
    [
        ("GetElementOfVector", {"vector_in": [1.0, 2.0], "index": 5}, "index", "valid indices are 0..1"),
        ("GetElementOfVector", {"vector_in": [], "index": 0}, "index", "the vector is empty"),
        ("RemoveFromVector", {"input_vector": [1.0], "index": 3}, "index", "valid indices are 0..0"),
        (
            "InsertInVector",
            {"input_vector": [1.0], "index": 4, "element": 2.0},
            "index",
            "valid indices are 0..1",
        ),
        ("PushBackVector", {"input_vector": ["a"], "element": 1.0}, "element", "holds string elements"),
        ("GetSizeOfVector", {"vector_in": 3}, "vector_in", "expected a vector"),
        ("CreatePoseStamped", {"position_xyz": [1.0, 2.0]}, "position_xyz", "expected 3 values x;y;z"),
        ("CreateTwistStamped", {"angular_velocity_xyz": [1.0]}, "angular_velocity_xyz", "expected 3 values"),
        ("UnpackPoseStampedMessage", {"pose_stamped": "not a pose"}, "pose_stamped", "geometry_msgs"),
        ("UnpackRobotStateMessage", {"robot_state": 7}, "robot_state", "RobotJointState"),
    ],
)
def test_bad_input_fails_the_behavior_naming_port_value_and_alternatives(
    behavior: Any,
    context: BehaviorContext,
    behavior_id: str,
    inputs: dict[str, Any],
    port: str,
    expected: str,
) -> None:
    run = tick_behavior(behavior(behavior_id), inputs, context=context)
    assert run.status == NodeStatus.FAILURE
    message = run.toasts[-1]
    assert f"port [{port}]" in message and expected in message, message


def test_a_wrong_message_type_on_a_typed_port_is_refused_when_the_tree_is_built(
    registry: Any, context: BehaviorContext
) -> None:
    from kinema.errors import KinemaError

    body = """
        <Action ID="CreateTwistStamped" twist_stamped="{t}"/>
        <Action ID="UnpackPoseStampedMessage" pose_stamped="{t}"/>
    """
    with pytest.raises(KinemaError) as error:
        run_objective(_xml(body), registry=registry, context=context)
    assert "geometry_msgs::msg::TwistStamped" in str(error.value)
    assert "geometry_msgs::msg::PoseStamped" in str(error.value)


def test_messages_are_created_and_unpacked(behavior: Any, context: BehaviorContext) -> None:
    twist = tick_behavior(
        behavior("CreateTwistStamped"),
        {
            "reference_frame": "tool0",
            "linear_velocity_xyz": [0.1, 0.0, 0.0],
            "angular_velocity_xyz": [0.0, 0.0, 1.0],
        },
        context=context,
    ).outputs["twist_stamped"]
    assert twist.header.frame_id == "tool0" and twist.twist.linear.x == 0.1 and twist.twist.angular.z == 1.0
    unpacked = tick_behavior(behavior("UnpackTwistStampedMessage"), {"twist_stamped": twist}, context=context)
    assert unpacked.outputs["twist"].angular.z == 1.0
    wrench = tick_behavior(
        behavior("CreateWrenchStamped"),
        {"force_xyz": [0.0, 0.0, -5.0], "torque_xyz": [0.0, 0.0, 0.0]},
        context=context,
    ).outputs["wrench_stamped"]
    assert wrench.wrench.force.z == -5.0
    assert (
        tick_behavior(behavior("UnpackWrenchStampedMessage"), {"wrench_stamped": wrench}, context=context)
        .outputs["wrench"]
        .force.z
        == -5.0
    )
    string = tick_behavior(behavior("CreateStringMessage"), {"data": "hello"}, context=context).outputs[
        "string"
    ]
    assert (
        tick_behavior(behavior("UnpackStringMessage"), {"string": string}, context=context).outputs["data"]
        == "hello"
    )
    state = tick_behavior(
        behavior("CreateRobotState"), {"joint_names": ["elbow_joint"], "positions": [0.5]}, context=context
    ).outputs["robot_state"]
    assert state.__msgtype__ == "moveit_studio_agent_msgs/msg/RobotJointState"
    joints = tick_behavior(behavior("UnpackRobotStateMessage"), {"robot_state": state}, context=context)
    assert list(joints.outputs["joint_state"].name) == ["elbow_joint"]


def test_collision_and_graspable_objects_unpack(behavior: Any, context: BehaviorContext) -> None:
    from kinema.transport import from_dict

    box = from_dict(
        "moveit_msgs/msg/CollisionObject",
        {
            "header": {"frame_id": "world"},
            "id": "table",
            "primitives": [{"type": 1, "dimensions": [1.0, 2.0, 0.1]}],
            "primitive_poses": [{"position": {"z": 0.5}, "orientation": {"w": 1.0}}],
        },
    )
    graspable = tick_behavior(
        behavior("CreateGraspableObjectMessage"), {"object": box, "grasp_info": "top"}, context=context
    ).outputs["graspable_object"]
    parts = tick_behavior(
        behavior("UnpackGraspableObjectMessage"), {"graspable_object": graspable}, context=context
    )
    assert parts.outputs["grasp_info"] == "top" and parts.outputs["object"].id == "table"
    fields = tick_behavior(
        behavior("UnpackCollisionObjectMessage"), {"collision_object": box}, context=context
    )
    assert fields.status == NodeStatus.SUCCESS, fields.toasts
    assert fields.outputs["id"] == "table" and fields.outputs["header"].frame_id == "world"
    assert list(fields.outputs["primitives"][0].dimensions) == [1.0, 2.0, 0.1]
    assert fields.outputs["primitive_poses"][0].position.z == 0.5 and fields.outputs["operation"] == 0


def test_writing_an_element_into_an_entry_of_another_type_fails_the_behavior(
    registry: Any, context: BehaviorContext
) -> None:
    body = (
        POSES
        + """
        <Action ID="GetSizeOfVector" vector_in="{poses}" vector_size="{n}"/>
        <Action ID="GetElementOfVector" vector_in="{poses}" index="0" element="{n}"/>
        """
    )
    result = run_objective(_xml(body), registry=registry, context=context)
    assert result.status == NodeStatus.FAILURE
    message = result.toasts[-1]
    assert "port [element] cannot take a geometry_msgs/msg/PoseStamped message" in message, message
    assert "[int]" in message, message


def test_a_collision_object_is_created_from_its_fields_and_unpacks_to_them(
    behavior: Any, context: BehaviorContext
) -> None:
    from kinema.transport import from_dict

    box = from_dict("shape_msgs/msg/SolidPrimitive", {"type": 1, "dimensions": [0.1, 0.2, 0.3]})
    where = from_dict("geometry_msgs/msg/Pose", {"position": {"z": 0.4}, "orientation": {"w": 1.0}})
    header = from_dict("std_msgs/msg/Header", {"frame_id": "world"})
    created = tick_behavior(
        behavior("CreateCollisionObjectMessage"),
        {"id": "crate", "header": header, "primitives": [box], "primitive_poses": [where]},
        context=context,
    )
    assert created.status == NodeStatus.SUCCESS, created.toasts
    crate = created.outputs["collision_object"]
    fields = tick_behavior(
        behavior("UnpackCollisionObjectMessage"), {"collision_object": crate}, context=context
    )
    assert fields.outputs["id"] == "crate" and fields.outputs["header"].frame_id == "world"
    assert list(fields.outputs["primitives"][0].dimensions) == pytest.approx([0.1, 0.2, 0.3])
    assert fields.outputs["primitive_poses"][0].position.z == 0.4
    missing_pose = tick_behavior(
        behavior("CreateCollisionObjectMessage"), {"id": "crate", "primitives": [box]}, context=context
    )
    assert missing_pose.status == NodeStatus.FAILURE
    assert "port [primitive_poses] has 0 poses for 1 primitives" in missing_pose.toasts[-1]
