"""An action's send_goal request and response laid out directly are what the generic serializer makes."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from kinema.interfaces import load_interfaces
from kinema.transport.messages import from_dict
from kinema.transport.send_goal_cdr import (
    read_send_goal_request,
    read_send_goal_response,
    response_reader,
    send_goal_request,
    send_goal_response,
)

GOAL_ID = bytes(range(3, 19))
# Goals whose fields need every alignment: strings and sequences (4), doubles and durations (8), bools (1).
GOALS: list[tuple[str, dict[str, Any]]] = [
    ("example_interfaces/action/Fibonacci", {"order": 7}),
    (
        "moveit_studio_sdk_msgs/action/DoObjectiveSequence",
        {
            "objective_name": "Pick é",
            "objective_xml_string": "<root/>",
            "parameter_overrides": [
                {"description": {"name": "x", "type": 2}, "double_value": 0.25},
                {"description": {"name": "flag", "type": 4}, "bool_value": True},
            ],
        },
    ),
    ("control_msgs/action/GripperCommand", {"command": {"position": 0.04, "max_effort": 10.0}}),
    (
        "control_msgs/action/FollowJointTrajectory",
        {
            "trajectory": {
                "joint_names": ["a", "bc"],
                "points": [{"positions": [0.5, 1.5], "time_from_start": {"sec": 1, "nanosec": 5}}],
            },
            "goal_time_tolerance": {"sec": 2, "nanosec": 0},
        },
    ),
]


@pytest.mark.parametrize(("action_type", "goal"), GOALS, ids=[name for name, _ in GOALS])
def test_the_request_is_the_generic_one(action_type: str, goal: dict[str, Any]) -> None:
    registry = load_interfaces()
    action = registry.action(action_type)
    goal_message = from_dict(action.goal, goal)
    request = registry.message_class(action.send_goal.request)(
        goal_id=registry.message_class("unique_identifier_msgs/msg/UUID")(
            uuid=np.frombuffer(GOAL_ID, dtype=np.uint8).copy()
        ),
        goal=goal_message,
    )
    generic = registry.serialize(request, action.send_goal.request)
    assert send_goal_request(GOAL_ID, registry.serialize(goal_message, action.goal)) == generic
    # A server reads the UUID where it lies and the goal behind it as the generic deserializer reads it.
    read = read_send_goal_request(generic)
    assert read is not None and read[0] == GOAL_ID
    goal_read = registry.deserialize(generic, action.send_goal.request).goal
    assert read[1] == registry.serialize(goal_read, action.goal)


@pytest.mark.parametrize("accepted", [True, False])
@pytest.mark.parametrize("stamp", [(0, 0), (1_700_000_000, 999_999_999), (-3, 7)])
def test_the_response_reads_as_the_generic_deserializer_reads_it(
    accepted: bool, stamp: tuple[int, int]
) -> None:
    registry = load_interfaces()
    response_type = registry.action("example_interfaces/action/Fibonacci").send_goal.response
    payload = registry.serialize(
        from_dict(response_type, {"accepted": accepted, "stamp": {"sec": stamp[0], "nanosec": stamp[1]}}),
        response_type,
    )
    assert read_send_goal_response(payload) == (accepted, *stamp)
    assert send_goal_response(accepted, *stamp) == payload
    assert response_reader(registry, response_type)(payload) == registry.deserialize(payload, response_type)


def test_a_big_endian_response_goes_to_the_generic_deserializer() -> None:
    registry = load_interfaces()
    response_type = registry.action("example_interfaces/action/Fibonacci").send_goal.response
    big_endian = b"\x00\x00\x00\x00" + b"\x01\x00\x00\x00" + (5).to_bytes(4, "big") + (9).to_bytes(4, "big")
    assert read_send_goal_response(big_endian) is None
    message = response_reader(registry, response_type)(big_endian)
    assert message.accepted and (message.stamp.sec, message.stamp.nanosec) == (5, 9)


def test_a_big_endian_request_goes_to_the_generic_deserializer() -> None:
    assert read_send_goal_request(b"\x00\x00\x00\x00" + GOAL_ID + b"\x00\x00\x00\x07") is None
    assert read_send_goal_request(b"\x00\x01\x00\x00" + GOAL_ID[:8]) is None  # too short for a UUID
