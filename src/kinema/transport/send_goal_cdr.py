"""An action's ``send_goal`` request and response laid out directly, for the hot path of both sides.

Every action's ``Name_SendGoal`` has the same frame: the request is the goal's UUID (16 bytes) followed by
the goal, the response a bool and a ``builtin_interfaces/Time``. A client sending a goal used to build the
UUID as a numpy array inside a request object, and read the response through the generic deserializer;
both showed in the round trip of a trivial objective. Here the request is the goal's own CDR behind the
UUID (the goal starts at offset 16, a multiple of every CDR alignment, so its bytes are the same either
way), and the response is read as the two fixed fields it is. A server reads the UUID straight from the
request and deserialises only the goal behind it, and writes its response as those two fields. The tests
check all of it against the generic serializer.
"""

from __future__ import annotations

import struct
from typing import Any

CDR_LE_HEADER = b"\x00\x01\x00\x00"
# accepted (bool), 3 bytes of padding, stamp.sec (int32), stamp.nanosec (uint32).
_RESPONSE = struct.Struct("<?3xiI")
_RESPONSE_SIZE = len(CDR_LE_HEADER) + _RESPONSE.size
_GOAL_AT = len(CDR_LE_HEADER) + 16


def send_goal_request(goal_id: bytes, goal_cdr: bytes) -> bytes:
    """The request payload for ``goal_id`` (16 bytes) and the goal's little-endian CDR payload."""
    if len(goal_id) != 16 or goal_cdr[:4] != CDR_LE_HEADER:
        raise ValueError("send_goal_request needs a 16-byte goal id and a little-endian CDR goal")
    return CDR_LE_HEADER + goal_id + goal_cdr[4:]


def read_send_goal_request(payload: bytes) -> tuple[bytes, bytes] | None:
    """``(goal_id, goal_cdr)`` of a little-endian request payload, the goal as a payload of its own (the
    inverse of :func:`send_goal_request`); None for another encoding (the caller then uses the generic
    deserializer)."""
    if len(payload) < _GOAL_AT or payload[:4] != CDR_LE_HEADER:
        return None
    return payload[4:_GOAL_AT], CDR_LE_HEADER + payload[_GOAL_AT:]


def send_goal_response(accepted: bool, sec: int, nanosec: int) -> bytes:
    """The little-endian response payload: whether the goal was accepted, and when."""
    return CDR_LE_HEADER + _RESPONSE.pack(accepted, sec, nanosec)


def read_send_goal_response(payload: bytes) -> tuple[bool, int, int] | None:
    """``(accepted, sec, nanosec)`` of a little-endian response payload; None for another encoding (the
    caller then uses the generic deserializer)."""
    if len(payload) != _RESPONSE_SIZE or payload[:4] != CDR_LE_HEADER:
        return None
    accepted, sec, nanosec = _RESPONSE.unpack_from(payload, 4)
    return bool(accepted), sec, nanosec


def response_reader(registry: Any, response_type: str) -> Any:
    """``decode(payload)`` giving the ``response_type`` message, directly when the layout allows."""
    response_class = registry.message_class(response_type)
    time_class = registry.message_class("builtin_interfaces/msg/Time")

    def decode(payload: bytes) -> Any:
        fields = read_send_goal_response(payload)
        if fields is None:
            return registry.deserialize(payload, response_type)
        accepted, sec, nanosec = fields
        return response_class(accepted=accepted, stamp=time_class(sec=sec, nanosec=nanosec))

    return decode
