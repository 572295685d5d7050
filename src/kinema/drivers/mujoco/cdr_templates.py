"""Pre-laid-out CDR payloads for the messages the physics thread publishes at every publish period.

``/joint_states`` always names the same joints, so everything but the stamp and the three number arrays
is fixed; a force/torque broadcaster's ``WrenchStamped`` always has the same frame id. Filling a
template costs a few microseconds, where the generic serializer takes about a hundred — at
``--sim-speed max`` that is the difference between publishing and stepping. Each encoder checks itself
against the generic serializer when built, so a layout mistake fails loudly at start.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from kinema.errors import DriverError

# CDR little endian (XCDR1), as rmw_zenoh writes it.
_ENCAPSULATION = b"\x00\x01\x00\x00"
_STAMP = struct.Struct("<iI")
_FLOAT64 = np.dtype("<f8")


def _split_stamp(seconds: float) -> tuple[int, int]:
    nanoseconds = round(seconds * 1e9)
    return nanoseconds // 1_000_000_000, nanoseconds % 1_000_000_000


def _align(offset: int, size: int) -> int:
    return (offset + size - 1) // size * size


class ClockEncoder:
    """``rosgraph_msgs/msg/Clock`` payloads."""

    def __init__(self, serialize: Callable[[float], bytes]) -> None:
        _check(self.encode(12.5), serialize(12.5), "rosgraph_msgs/msg/Clock")

    @staticmethod
    def encode(seconds: float) -> bytes:
        """The CDR payload of a Clock at ``seconds`` of sim time."""
        return _ENCAPSULATION + _STAMP.pack(*_split_stamp(seconds))


class JointStateEncoder:
    """``sensor_msgs/msg/JointState`` payloads for a fixed list of joint names and an empty frame id.

    Args:
        names: the joint names, in the order of the arrays passed to :meth:`encode`.
        serialize: the generic serializer, ``serialize(stamp, names, position, velocity, effort)``,
            used once to check the layout.
    """

    def __init__(self, names: Sequence[str], serialize: Callable[..., bytes]) -> None:
        self.count = len(names)
        body = bytearray(_STAMP.pack(0, 0))
        body += struct.pack("<I", 1) + b"\x00"  # frame_id: "" (length includes the terminating NUL)
        body += bytes(_align(len(body), 4) - len(body))
        body += struct.pack("<I", len(names))
        for name in names:
            encoded = name.encode("utf-8") + b"\x00"
            body += bytes(_align(len(body), 4) - len(body))
            body += struct.pack("<I", len(encoded)) + encoded
        self._arrays: list[int] = []
        for _ in range(3):
            body += bytes(_align(len(body), 4) - len(body))
            body += struct.pack("<I", self.count)
            body += bytes(_align(len(body), 8) - len(body))
            self._arrays.append(len(_ENCAPSULATION) + len(body))
            body += bytes(8 * self.count)
        self._template = bytes(_ENCAPSULATION + body)
        # The fixed bytes around the stamp and the arrays, joined with them at every encode.
        size = 8 * self.count
        stamp_end = len(_ENCAPSULATION) + _STAMP.size
        ends = [offset + size for offset in self._arrays]
        self._fixed = (
            self._template[: len(_ENCAPSULATION)],
            self._template[stamp_end : self._arrays[0]],
            self._template[ends[0] : self._arrays[1]],
            self._template[ends[1] : self._arrays[2]],
        )
        sample = np.linspace(-1.0, 1.0, self.count)
        _check(
            self.encode(3.25, sample, 2 * sample, 3 * sample),
            serialize(3.25, list(names), sample, 2 * sample, 3 * sample),
            "sensor_msgs/msg/JointState",
        )

    def encode(self, seconds: float, position: np.ndarray, velocity: np.ndarray, effort: np.ndarray) -> bytes:
        """The CDR payload of a JointState stamped ``seconds`` (each array has one value per name)."""
        encapsulation, after_stamp, after_position, after_velocity = self._fixed
        return b"".join(
            (
                encapsulation,
                _STAMP.pack(*_split_stamp(seconds)),
                after_stamp,
                _doubles(position, self.count),
                after_position,
                _doubles(velocity, self.count),
                after_velocity,
                _doubles(effort, self.count),
            )
        )


class WrenchStampedEncoder:
    """``geometry_msgs/msg/WrenchStamped`` payloads for a fixed frame id.

    Args:
        frame_id: the header's frame id.
        serialize: the generic serializer, ``serialize(sec, nanosec, frame_id, wrench)``, used once to
            check the layout.
    """

    def __init__(self, frame_id: str, serialize: Callable[[int, int, str, np.ndarray], bytes]) -> None:
        body = bytearray(_STAMP.pack(0, 0))
        encoded = frame_id.encode("utf-8") + b"\x00"
        body += struct.pack("<I", len(encoded)) + encoded
        body += bytes(_align(len(body), 8) - len(body))
        self._wrench = len(_ENCAPSULATION) + len(body)
        body += bytes(8 * 6)
        self._template = bytes(_ENCAPSULATION + body)
        self._frame = self._template[len(_ENCAPSULATION) + _STAMP.size : self._wrench]
        sample = np.array([1.5, -2.25, 3.0, -0.125, 0.5, 7.75])
        _check(
            self.encode(3, 250_000_000, sample),
            serialize(3, 250_000_000, frame_id, sample),
            "geometry_msgs/msg/WrenchStamped",
        )

    def encode(self, sec: int, nanosec: int, wrench: np.ndarray) -> bytes:
        """The CDR payload stamped ``sec``/``nanosec`` with force x, y, z then torque x, y, z."""
        return b"".join((_ENCAPSULATION, _STAMP.pack(sec, nanosec), self._frame, _doubles(wrench, 6)))


def wrench_serializer(registry: Any) -> Callable[[int, int, str, np.ndarray], bytes]:
    """The generic serializer of WrenchStamped through ``registry`` (to check the template against)."""
    types = registry.typestore.types

    def wrench_stamped(sec: int, nanosec: int, frame_id: str, wrench: np.ndarray) -> bytes:
        vector = types["geometry_msgs/msg/Vector3"]
        values = [float(v) for v in wrench]
        message = types["geometry_msgs/msg/WrenchStamped"](
            header=types["std_msgs/msg/Header"](
                stamp=types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec), frame_id=frame_id
            ),
            wrench=types["geometry_msgs/msg/Wrench"](force=vector(*values[:3]), torque=vector(*values[3:])),
        )
        return bytes(registry.serialize(message, "geometry_msgs/msg/WrenchStamped"))

    return wrench_stamped


def _doubles(values: np.ndarray, count: int) -> bytes:
    """``count`` little-endian float64 values (a float64 array is taken as it is: no conversion)."""
    if isinstance(values, np.ndarray) and values.dtype == _FLOAT64 and values.shape == (count,):
        return values.tobytes()
    array = np.ascontiguousarray(values, dtype=_FLOAT64)
    if array.shape != (count,):
        raise ValueError(f"expected {count} values, got an array of shape {array.shape}")
    return array.tobytes()


def _check(fast: bytes, generic: bytes, type_name: str) -> None:
    if fast != generic:
        raise DriverError(f"internal error: the {type_name} template does not match the CDR serializer")


def generic_serializers(registry: Any) -> tuple[Callable[[float], bytes], Callable[..., bytes]]:
    """Serializers of Clock and JointState through ``registry`` (to check the templates against)."""
    types = registry.typestore.types
    time_type = types["builtin_interfaces/msg/Time"]

    def stamp(seconds: float) -> Any:
        sec, nanosec = _split_stamp(seconds)
        return time_type(sec=sec, nanosec=nanosec)

    def clock(seconds: float) -> bytes:
        message = types["rosgraph_msgs/msg/Clock"](clock=stamp(seconds))
        return bytes(registry.serialize(message, "rosgraph_msgs/msg/Clock"))

    def joint_state(seconds: float, names: list[str], position: Any, velocity: Any, effort: Any) -> bytes:
        message = types["sensor_msgs/msg/JointState"](
            header=types["std_msgs/msg/Header"](stamp=stamp(seconds), frame_id=""),
            name=names,
            position=np.asarray(position, dtype=float),
            velocity=np.asarray(velocity, dtype=float),
            effort=np.asarray(effort, dtype=float),
        )
        return bytes(registry.serialize(message, "sensor_msgs/msg/JointState"))

    return clock, joint_state
