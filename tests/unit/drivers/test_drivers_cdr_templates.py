"""The pre-laid-out /clock and /joint_states payloads equal what the generic CDR serializer writes."""

from __future__ import annotations

import numpy as np
import pytest

from kinema.drivers.mujoco.cdr_templates import ClockEncoder, JointStateEncoder, generic_serializers
from kinema.interfaces import load_interfaces


@pytest.fixture(scope="module")
def serializers() -> tuple[object, object]:
    return generic_serializers(load_interfaces())


@pytest.mark.parametrize(
    "names",
    [
        ["a"],
        ["linear_rail_joint", "shoulder_pan_joint", "robotiq_85_left_knuckle_joint"],
        ["x" * n for n in range(1, 9)],  # every string length modulo the 4-byte alignment
        ["gelenk_ä", "関節"],
    ],
)
def test_joint_state_payloads_match_the_serializer(
    serializers: tuple[object, object], names: list[str]
) -> None:
    _, joint_state = serializers
    encoder = JointStateEncoder(names, joint_state)  # type: ignore[arg-type]
    rng = np.random.default_rng(7)
    for stamp in (0.0, 0.002, 1234.5678, 86400.999999999):
        position, velocity, effort = rng.normal(size=(3, len(names)))
        assert encoder.encode(stamp, position, velocity, effort) == joint_state(  # type: ignore[operator]
            stamp, names, position, velocity, effort
        )


def test_payloads_deserialize_to_the_values(serializers: tuple[object, object]) -> None:
    _, joint_state = serializers
    names = ["elbow_joint", "wrist_1_joint"]
    payload = JointStateEncoder(names, joint_state).encode(3.5, np.array([1.0, 2.0]), np.zeros(2), np.ones(2))  # type: ignore[arg-type]
    message = load_interfaces().deserialize(payload, "sensor_msgs/msg/JointState")
    assert list(message.name) == names
    assert message.header.stamp.sec == 3 and message.header.stamp.nanosec == 500_000_000
    assert message.position.tolist() == [1.0, 2.0]


def test_clock_payloads_match_the_serializer(serializers: tuple[object, object]) -> None:
    clock, _ = serializers
    encoder = ClockEncoder(clock)  # type: ignore[arg-type]
    for stamp in (0.0, 0.01, 99.999999999, 1e6 + 0.5):
        assert encoder.encode(stamp) == clock(stamp)  # type: ignore[operator]


class _Data:
    """What the broadcaster reads of MjData: the time and the sensor values."""

    def __init__(self, time: float, sensordata: np.ndarray) -> None:
        self.time = time
        self.sensordata = sensordata


class _Sensor:
    def __init__(self, frame_id: str) -> None:
        self.frame_id = frame_id

    def read(self, data: _Data) -> np.ndarray:
        return data.sensordata


@pytest.mark.parametrize("frame_id", ["", "tool0", "x" * 5, "x" * 6, "x" * 7, "sensor_ä"])
def test_wrench_payloads_match_what_the_broadcaster_publishes(frame_id: str) -> None:
    """The template's bytes equal the broadcaster's message dict through the generic publisher path."""
    from kinema.drivers.mujoco.cdr_templates import WrenchStampedEncoder, wrench_serializer
    from kinema.drivers.mujoco.force_control import ForceTorqueSensorBroadcaster
    from kinema.transport import from_dict

    registry = load_interfaces()
    encoder = WrenchStampedEncoder(frame_id, wrench_serializer(registry))
    broadcaster = ForceTorqueSensorBroadcaster("ft", _Sensor(frame_id))  # type: ignore[arg-type]
    rng = np.random.default_rng(3)
    for now in (0.0, 0.002, 1234.5678, 1.9999999999, 86400.999999999):
        data = _Data(now, rng.normal(size=6))
        generic = registry.serialize(
            from_dict("geometry_msgs/msg/WrenchStamped", broadcaster.message(data)),
            "geometry_msgs/msg/WrenchStamped",
        )
        sec, nanosec = broadcaster.stamp(data)
        assert encoder.encode(sec, nanosec, broadcaster.sensor.read(data)) == bytes(generic)
