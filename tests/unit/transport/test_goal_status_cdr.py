"""GoalStatusArray payloads laid out directly are byte for byte what the generic serializer makes."""

from __future__ import annotations

import struct

import pytest

from kinema.interfaces import load_interfaces
from kinema.transport.goal_status_cdr import decode_goal_statuses, encode_goal_statuses
from kinema.transport.messages import from_dict

TYPE = "action_msgs/msg/GoalStatusArray"
# (goal id, sec, nanosec, status): odd sizes and offsets exercise the padding before each stamp
GOALS = [
    (bytes(range(16)), 1_700_000_000, 999_999_999, 1),
    (bytes(range(16, 32)), 0, 0, 4),
    (b"\xff" * 16, -5, 7, 6),
    (bytes(16), 2_000_000_000, 1, 0),
]


def _generic(goals: list[tuple[bytes, int, int, int]]) -> bytes:
    message = from_dict(
        TYPE,
        {
            "status_list": [
                {"goal_info": {"goal_id": {"uuid": list(g)}, "stamp": {"sec": s, "nanosec": n}}, "status": st}
                for g, s, n, st in goals
            ]
        },
    )
    return load_interfaces().serialize(message, TYPE)


@pytest.mark.parametrize("count", range(len(GOALS) + 1))
def test_the_payload_is_the_generic_serializers_and_reads_back(count: int) -> None:
    goals = GOALS[:count]
    payload = encode_goal_statuses(goals)
    assert payload == _generic(goals)
    statuses = decode_goal_statuses(payload)
    assert statuses is not None
    assert list(statuses) == [(g, st) for g, _, _, st in goals]


def test_another_encoding_is_left_to_the_generic_deserializer() -> None:
    big_endian = b"\x00\x00\x00\x00" + encode_goal_statuses(GOALS)[4:]
    assert decode_goal_statuses(big_endian) is None


def test_a_payload_cut_short_raises() -> None:
    statuses = decode_goal_statuses(encode_goal_statuses(GOALS)[:-20])
    assert statuses is not None
    with pytest.raises(struct.error):
        list(statuses)
