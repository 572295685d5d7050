"""RIHS01 hashes against values published by ROS 2 (rmw_zenoh design doc, `ros2 topic info -v`)."""

from __future__ import annotations

import pytest

from kinema.interfaces import load_interfaces

KNOWN = [
    (
        "std_msgs/msg/String",
        "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18",
    ),
    (
        "sensor_msgs/msg/JointState",
        "RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e",
    ),
    (
        "example_interfaces/srv/AddTwoInts",
        "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a",
    ),
    (
        "action_msgs/msg/GoalStatusArray",
        "RIHS01_6c1684b00f177d37438febe6e709fc4e2b0d4248dca4854946f9ed8b30cda83e",
    ),
    (
        "example_interfaces/action/Fibonacci_FeedbackMessage",
        "RIHS01_c1de71afd52e49a89c53d8262366884185bc0a02f78ce051c4e46b0a7fe59bb2",
    ),
    (
        "example_interfaces/action/Fibonacci_SendGoal_Request",
        "RIHS01_3d088942b413247db536576f0286768c6be8fcd5d0c9a5d544f359fba090a238",
    ),
    (
        "example_interfaces/action/Fibonacci_GetResult_Request",
        "RIHS01_c8a4f5e7d13b81286ee1043e2ecd084281cecf1ff06aaa799464f5f15479f003",
    ),
    (
        "action_msgs/srv/CancelGoal_Request",
        "RIHS01_3d3c84653c1f96918086887e1dcb236faec88b81a5b14fd4cf4840065bcdf8af",
    ),
]


@pytest.mark.parametrize(("type_name", "expected"), KNOWN)
def test_hash_matches_ros(type_name: str, expected: str) -> None:
    assert load_interfaces().type_hash(type_name) == expected


def test_service_hash_is_the_service_wrapper_not_the_request() -> None:
    registry = load_interfaces()
    service = registry.service("example_interfaces/srv/AddTwoInts")
    assert service.type_hash == registry.type_hash("example_interfaces/srv/AddTwoInts")
    assert service.type_hash != registry.type_hash(service.request)


def test_action_parts_use_their_own_types_and_hashes() -> None:
    action = load_interfaces().action("example_interfaces/action/Fibonacci")
    assert action.send_goal.dds_name == "example_interfaces::action::dds_::Fibonacci_SendGoal_"
    assert action.get_result.dds_name == "example_interfaces::action::dds_::Fibonacci_GetResult_"
    assert action.cancel_goal.dds_name == "action_msgs::srv::dds_::CancelGoal_"
    assert action.feedback_message_hash == KNOWN[4][1]
    assert action.status_hash == KNOWN[3][1]
    assert len({action.send_goal.type_hash, action.get_result.type_hash, action.cancel_goal.type_hash}) == 3
