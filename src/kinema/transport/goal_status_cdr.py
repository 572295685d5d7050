"""``action_msgs/msg/GoalStatusArray`` payloads laid out and read directly, for every goal of an action.

An action server publishes the status of every goal it still remembers (up to 100 finished ones) each time
a goal changes status, three times per goal; each client decodes every message. Through the generic CDR
serializer a 100-goal array cost about 0.3 ms to build and as much to read, which made a trivial objective
started through the SDK take twice as long as it needed. The layout is fixed and small, so it is written
here once, checked against the generic serializer by the tests, and read back the same way. Payloads in
another encoding (big-endian CDR from some other implementation) go through the generic deserializer.

Layout after the 4-byte encapsulation header (CDR little endian, offsets from the end of the header): the
element count (uint32), then per element the goal UUID (16 bytes, alignment 1), the stamp's ``sec``
(int32) and ``nanosec`` (uint32) aligned to 4, and the status (int8).

So the first element takes 25 bytes (its UUID ends 4-aligned) and every later one 28 (its UUID starts one
byte past a multiple of 4 and is followed by 3 bytes of padding): :func:`status_chunk` lays an element out
in the 28-byte form once, :func:`payload_of_chunks` joins them, and :func:`statuses_of` finds given goals
in a payload without reading the others.
"""

from __future__ import annotations

import struct
from collections.abc import Iterable, Iterator

CDR_LE_HEADER = b"\x00\x01\x00\x00"
_HEADER = len(CDR_LE_HEADER)
_COUNT = struct.Struct("<I")
_STAMP = struct.Struct("<iI")
_STAMP_AND_STATUS = struct.Struct("<iIb")
# Where the elements start in a payload (header included), and where the status lies in each.
_FIRST = _HEADER + _COUNT.size
_SECOND = _FIRST + 25
_CHUNK = 28
_PAD = b"\x00\x00\x00"


def encode_goal_statuses(goals: Iterable[tuple[bytes, int, int, int]]) -> bytes:
    """The CDR payload of a GoalStatusArray of ``(goal_id, sec, nanosec, status)`` tuples."""
    items = list(goals)
    out = bytearray(CDR_LE_HEADER)
    out += _COUNT.pack(len(items))
    for goal_id, sec, nanosec, status in items:
        out += goal_id
        pad = -(len(out) - _HEADER) % 4
        if pad:
            out += bytes(pad)
        out += _STAMP_AND_STATUS.pack(sec, nanosec, status)
    return bytes(out)


def decode_goal_statuses(payload: bytes) -> Iterator[tuple[bytes, int]] | None:
    """``(goal_id, status)`` for each element of a little-endian GoalStatusArray payload.

    Returns None for a payload this reader does not handle (another encoding); the caller then decodes it
    with the generic deserializer.

    Raises:
        struct.error: the payload is cut short.
    """
    if payload[:_HEADER] != CDR_LE_HEADER:
        return None
    return _elements(payload)


def _elements(payload: bytes) -> Iterator[tuple[bytes, int]]:
    view = memoryview(payload)[_HEADER:]
    (count,) = _COUNT.unpack_from(view, 0)
    offset = _COUNT.size
    for _ in range(count):
        goal_id = bytes(view[offset : offset + 16])
        if len(goal_id) != 16:
            raise struct.error("GoalStatusArray payload cut short")
        offset += 16
        offset += -offset % 4
        offset += _STAMP.size
        if offset >= len(view):
            raise struct.error("GoalStatusArray payload cut short")
        status = view[offset]
        if status >= 128:  # int8
            status -= 256
        offset += 1
        yield goal_id, status


def status_chunk(goal_id: bytes, sec: int, nanosec: int, status: int) -> bytes:
    """One element in the form every element after the first takes (28 bytes)."""
    return goal_id + _PAD + _STAMP_AND_STATUS.pack(sec, nanosec, status)


def payload_of_chunks(count: int, chunks: bytes) -> bytes:
    """The payload of ``count`` elements given as their :func:`status_chunk` forms, concatenated."""
    head = CDR_LE_HEADER + _COUNT.pack(count)
    if not count:
        return head
    # The first element's UUID ends 4-aligned: it has no padding.
    return b"".join((head, chunks[:16], chunks[19:]))


def statuses_of(payload: bytes, goal_ids: Iterable[bytes]) -> dict[bytes, int] | None:
    """The status of each of ``goal_ids`` that a little-endian GoalStatusArray payload lists.

    Cheaper than reading every element when a client follows a few goals of a server that remembers a
    hundred. Returns None for another encoding (see :func:`decode_goal_statuses`).
    """
    if payload[:_HEADER] != CDR_LE_HEADER:
        return None
    found: dict[bytes, int] = {}
    size = len(payload)
    for goal_id in goal_ids:
        start = payload.find(goal_id, _FIRST)
        while start != -1:
            if start == _FIRST:
                at = start + 24
            elif start >= _SECOND and (start - _SECOND) % _CHUNK == 0:
                at = start + 27
            else:  # the bytes happen to appear elsewhere (inside a stamp, across elements)
                start = payload.find(goal_id, start + 1)
                continue
            if at < size:
                status = payload[at]
                found[goal_id] = status - 256 if status >= 128 else status
            break
    return found
