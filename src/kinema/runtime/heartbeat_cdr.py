"""``moveit_studio_agent_msgs/msg/ObjectiveServerStatus`` payloads (the heartbeat) laid out directly.

The agent publishes a heartbeat ten times a second and once per status change, three per objective run,
from the tick thread. Through the generic path (two Time objects, the message object, rosbags'
serializer) one cost tens of microseconds on a busy agent, the tick thread's largest share of a trivial
run after the result. The layout is fixed: two stamps (4-byte fields) and two strings, each a uint32
length (with its NUL) and its bytes, the first padded to 4 for the second's length. The encoder checks
itself against the generic serializer when built, so a layout mistake fails loudly at the first heartbeat
instead of on the wire.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import TYPE_CHECKING

from kinema.errors import TransportError

if TYPE_CHECKING:
    from kinema.interfaces import TypeRegistry

_ENCAPSULATION = b"\x00\x01\x00\x00"
_STAMPS = struct.Struct("<iIiI")

Serialize = Callable[[tuple[int, int], tuple[int, int], str, str], bytes]


def _cdr_string(text: str) -> bytes:
    """A CDR string at a 4-aligned offset: its length (with the NUL), its bytes, no padding after."""
    data = text.encode("utf-8") + b"\x00"
    return struct.pack("<I", len(data)) + data


class HeartbeatEncoder:
    """CDR payloads of ``ObjectiveServerStatus``.

    Args:
        serialize: the generic serializer, ``serialize(process_stamp, ros_stamp, objective_name,
            objective_status)`` with stamps as ``(sec, nanosec)``, used once to check the layout.

    Raises:
        TransportError: the layout does not match the generic serializer.
    """

    def __init__(self, serialize: Serialize) -> None:
        for sample in (((12, 250_000_000), (3, 5), "Pick \u00e9", "Running"), ((0, 0), (0, 0), "", "Idle")):
            if self.encode(*sample) != serialize(*sample):
                raise TransportError(
                    "internal error: the ObjectiveServerStatus layout does not match the CDR serializer"
                )

    def encode(
        self, process_stamp: tuple[int, int], ros_stamp: tuple[int, int], objective_name: str, status: str
    ) -> bytes:
        """The payload of one heartbeat; stamps as ``(sec, nanosec)``."""
        try:
            stamps = _STAMPS.pack(*process_stamp, *ros_stamp)
        except struct.error as error:
            raise TransportError(
                f"cannot serialise the heartbeat stamps {process_stamp}, {ros_stamp}: {error}"
            ) from error
        name = _cdr_string(objective_name)
        # The status string's length is 4-aligned: the stamps are 16 bytes, the name is padded.
        return b"".join((_ENCAPSULATION, stamps, name, bytes(-len(name) % 4), _cdr_string(status)))


def generic_serializer(registry: TypeRegistry, type_name: str) -> Serialize:
    """ObjectiveServerStatus through ``registry``'s message classes and serializer (to check the encoder)."""
    message_class = registry.message_class(type_name)
    time_class = registry.message_class("builtin_interfaces/msg/Time")

    def serialize(
        process_stamp: tuple[int, int], ros_stamp: tuple[int, int], objective_name: str, status: str
    ) -> bytes:
        message = message_class(
            process_timestamp=time_class(*process_stamp),
            ros_timestamp=time_class(*ros_stamp),
            objective_name=objective_name,
            objective_status=status,
        )
        return registry.serialize(message, type_name)

    return serialize
