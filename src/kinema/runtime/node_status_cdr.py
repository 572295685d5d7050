"""``kinema_msgs/msg/NodeStatusCodes`` payloads laid out directly, for the tick thread.

The agent publishes one of these after every tick that changed a status. Through the generic path (a
message object, then rosbags' serializer) that cost about 30 µs a tick whatever the size, more than
the rest of the message's work on a small tree. The layout is fixed: a string and a uint32 that stay
the same for a whole run, then three arrays of 4-byte items, so every field stays 4-aligned and the
codes go out as the bytes the batch already holds. The encoder checks itself against the generic
serializer when built, so a layout mistake fails loudly at the first message instead of on the wire.
"""

from __future__ import annotations

import struct
import sys
from collections.abc import Callable, Sequence
from typing import Any

from kinema.errors import TransportError

# CDR little endian (XCDR1), as rmw_zenoh writes it.
_ENCAPSULATION = b"\x00\x01\x00\x00"
_LITTLE = sys.byteorder == "little"


def time_parts(seconds: float) -> tuple[int, int]:
    """``(sec, nanosec)`` of a ``builtin_interfaces/Time`` for ``seconds``: every stamp the agent sends."""
    sec = int(seconds)
    return sec, int((seconds - sec) * 1e9)


class NodeStatusCodesEncoder:
    """CDR payloads of ``kinema_msgs/msg/NodeStatusCodes``.

    Args:
        serialize: the generic serializer, ``serialize(objective_name, table_id, stamps, starts, codes)``
            (stamps as seconds), used once to check the layout.

    Raises:
        TransportError: the layout does not match the generic serializer.
    """

    def __init__(self, serialize: Callable[[str, int, Sequence[float], Sequence[int], Any], bytes]) -> None:
        import numpy as np

        self._prefix_of: tuple[str, int] | None = None
        self._prefix = b""
        sample = ("Pick \u00e9", 7, [12.25, 1.0e9 + 0.5], [0, 2], np.array([5, 31, 2499, 0], dtype=np.uint32))
        if self.encode(*sample) != serialize(*sample):
            raise TransportError(
                "internal error: the NodeStatusCodes layout does not match the CDR serializer"
            )
        self._prefix_of = None

    def encode(
        self, objective_name: str, table_id: int, stamps: Sequence[float], starts: Sequence[int], codes: Any
    ) -> bytes:
        """The payload of one message: ``codes`` is a numpy ``uint32`` array, ``stamps`` in seconds."""
        if self._prefix_of != (objective_name, table_id):  # once per run
            name = objective_name.encode("utf-8") + b"\x00"
            padding = -(4 + len(name)) % 4
            self._prefix = _ENCAPSULATION + struct.pack("<I", len(name)) + name + bytes(padding)
            self._prefix += struct.pack("<I", table_id)
            self._prefix_of = (objective_name, table_id)
        count = len(stamps)
        values: list[int] = [count]
        for seconds in stamps:
            values.extend(time_parts(seconds))
        values.append(len(starts))
        values.extend(starts)
        values.append(len(codes))
        try:
            head = struct.pack(f"<I{'iI' * count}I{len(starts)}II", *values)
        except struct.error as error:
            raise TransportError(
                f"cannot serialise node status codes of {objective_name!r}: {error}"
            ) from error
        data = codes.tobytes() if _LITTLE else codes.astype("<u4").tobytes()
        return b"".join((self._prefix, head, data))


def generic_serializer(registry: Any) -> Callable[[str, int, Sequence[float], Sequence[int], Any], bytes]:
    """NodeStatusCodes through ``registry``'s message classes and serializer (to check the encoder)."""
    import numpy as np

    codes_class = registry.message_class("kinema_msgs/msg/NodeStatusCodes")
    time_class = registry.message_class("builtin_interfaces/msg/Time")

    def serialize(
        objective_name: str, table_id: int, stamps: Sequence[float], starts: Sequence[int], codes: Any
    ) -> bytes:
        message = codes_class(
            objective_name=objective_name,
            table_id=table_id,
            stamps=[time_class(*time_parts(seconds)) for seconds in stamps],
            starts=np.array(starts, dtype=np.uint32),
            codes=codes,
        )
        return registry.serialize(message, "kinema_msgs/msg/NodeStatusCodes")

    return serialize
