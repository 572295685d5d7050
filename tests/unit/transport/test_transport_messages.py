"""Building messages from dicts / YAML flow text and rendering them back, plus CDR bytes."""

from __future__ import annotations

import numpy as np
import pytest

from kinema.errors import TransportError
from kinema.interfaces import load_interfaces
from kinema.transport import from_dict, msg, parse_yaml_flow, to_dict, to_yaml, type_of


def test_missing_fields_get_ros_defaults() -> None:
    state = from_dict("sensor_msgs/msg/JointState", {"name": ["j1"]})
    assert state.header.frame_id == "" and state.header.stamp.sec == 0
    assert state.name == ["j1"]
    assert isinstance(state.position, np.ndarray) and state.position.size == 0


def test_yaml_flow_as_ros2_takes_it() -> None:
    request = parse_yaml_flow(
        "moveit_studio_sdk_msgs/srv/ExecuteObjective_Request",
        "{objective_name: 'Move to Waypoint', parameter_overrides: "
        "[{description: {name: waypoint_name, type: 0}, string_value: Home, behavior_namespaces: [move]}]}",
    )
    assert request.objective_name == "Move to Waypoint"
    (override,) = request.parameter_overrides
    assert (override.description.name, override.string_value, override.behavior_namespaces) == (
        "waypoint_name",
        "Home",
        ["move"],
    )
    assert type_of(request) == "moveit_studio_sdk_msgs/srv/ExecuteObjective_Request"


def test_round_trip_through_dict_and_yaml() -> None:
    pose = msg(
        "geometry_msgs/msg/PoseStamped",
        header={"frame_id": "world"},
        pose={"position": {"x": 1, "y": 2.5}, "orientation": {"w": 1.0}},
    )
    data = to_dict(pose)
    assert data["pose"]["position"] == {"x": 1.0, "y": 2.5, "z": 0.0}
    assert from_dict("geometry_msgs/msg/PoseStamped", data) == pose
    assert parse_yaml_flow("geometry_msgs/msg/PoseStamped", to_yaml(pose, flow=True)) == pose
    assert "frame_id: world" in to_yaml(pose)


def test_constants_are_class_attributes() -> None:
    codes = load_interfaces().message_class("moveit_msgs/msg/MoveItErrorCodes")
    assert (codes.SUCCESS, codes.FAILURE, codes.PREEMPTED) == (1, 99999, -7)


def test_echoed_messages_show_their_fields_not_their_constants() -> None:
    status = msg("moveit_studio_agent_msgs/msg/ObjectiveServerStatus", objective_status="Idle")
    assert list(to_dict(status)) == [
        "process_timestamp",
        "ros_timestamp",
        "objective_name",
        "objective_status",
    ]
    assert "OBJECTIVE_STATUS_IDLE" not in to_yaml(status)
    assert to_dict(msg("moveit_msgs/msg/MoveItErrorCodes", val=1)) == {"val": 1, "message": "", "source": ""}


@pytest.mark.parametrize(
    ("type_name", "text", "message"),
    [
        ("example_interfaces/srv/AddTwoInts_Request", "{a: 1, c: 2}", "has no field 'c' (valid: a, b)"),
        ("example_interfaces/srv/AddTwoInts_Request", "{a: one}", "a: expected int64, got str"),
        ("std_msgs/msg/String", "{data: [1]}", "data: expected string"),
        ("sensor_msgs/msg/JointState", "{position: 3}", "position: expected a list"),
        ("std_msgs/msg/String", "{data: [", "cannot parse"),
        ("std_msgs/msg/Strin", "{}", "did you mean 'std_msgs/msg/String'"),
    ],
)
def test_bad_values_are_explained(type_name: str, text: str, message: str) -> None:
    with pytest.raises(TransportError) as raised:
        parse_yaml_flow(type_name, text)
    assert message in str(raised.value)


def test_cdr_has_the_encapsulation_header() -> None:
    registry = load_interfaces()
    raw = registry.serialize(msg("std_msgs/msg/String", data="hello from rmwz"), "std_msgs/msg/String")
    assert raw == bytes.fromhex("000100001000000068656c6c6f2066726f6d20726d777a00")
    cancel = "moveit_studio_sdk_msgs/srv/CancelObjective_Request"
    empty = registry.serialize(from_dict(cancel), cancel)
    assert empty == bytes.fromhex("0001000000")  # an empty struct carries one dummy byte


def test_a_numpy_array_that_fits_the_field_is_taken_whole_and_one_that_does_not_is_checked() -> None:
    codes = np.arange(5, dtype=np.uint32)
    message = msg("kinema_msgs/msg/NodeStatusCodes", codes=codes)
    assert message.codes.dtype == np.uint32 and message.codes.tolist() == [0, 1, 2, 3, 4]
    widened = msg("kinema_msgs/msg/NodeStatusCodes", starts=np.array([1, 2], dtype=np.uint16))
    assert widened.starts.dtype == np.uint32 and widened.starts.tolist() == [1, 2]
    # int64 into uint32 is not a safe cast: each value is checked as a list's would be
    assert msg("kinema_msgs/msg/NodeStatusCodes", codes=np.array([7, 8])).codes.tolist() == [7, 8]
    with pytest.raises(TransportError):
        msg("kinema_msgs/msg/NodeStatusCodes", codes=np.array([-1]))
    with pytest.raises(TransportError):
        msg("kinema_msgs/msg/NodeStatusCodes", codes=np.zeros((2, 2), dtype=np.uint32))


def test_clock_payloads_decode_directly_to_what_the_generic_deserializer_makes() -> None:
    """/clock's 12-byte payloads take a short path; the message equals the generic decoder's."""
    import struct

    from kinema.interfaces import load_interfaces

    registry = load_interfaces()
    for sec, nanosec in ((0, 0), (12, 500_000_000), (-3, 999_999_999), (2**31 - 1, 1)):
        payload = b"\x00\x01\x00\x00" + struct.pack("<iI", sec, nanosec)
        fast = registry.deserialize(payload, "rosgraph_msgs/msg/Clock")
        generic = registry.typestore.deserialize_cdr(payload, "rosgraph_msgs/msg/Clock")
        assert fast == generic and type(fast) is type(generic)
        assert (fast.clock.sec, fast.clock.nanosec) == (sec, nanosec)
    # Big endian (and any other layout) still goes through the generic deserializer.
    big = b"\x00\x00\x00\x00" + struct.pack(">iI", 7, 8)
    decoded = registry.deserialize(big, "rosgraph_msgs/msg/Clock")
    assert (decoded.clock.sec, decoded.clock.nanosec) == (7, 8)
