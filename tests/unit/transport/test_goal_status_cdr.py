"""GoalStatusArray payloads laid out directly are byte for byte what the generic serializer makes."""

from __future__ import annotations

import struct

import pytest

from kinema.interfaces import load_interfaces
from kinema.transport.goal_status_cdr import (
    decode_goal_statuses,
    encode_goal_statuses,
    payload_of_chunks,
    status_chunk,
    statuses_of,
)
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


@pytest.mark.parametrize("count", range(len(GOALS) + 1))
def test_payloads_joined_from_chunks_are_the_generic_serializers(count: int) -> None:
    goals = GOALS[:count]
    chunks = b"".join(status_chunk(*goal) for goal in goals)
    assert payload_of_chunks(count, chunks) == _generic(goals)


def test_the_statuses_of_given_goals_are_found_without_reading_the_others() -> None:
    payload = encode_goal_statuses(GOALS)
    wanted = [GOALS[0][0], GOALS[2][0], GOALS[3][0], b"\x42" * 16]
    assert statuses_of(payload, wanted) == {GOALS[0][0]: 1, GOALS[2][0]: 6, GOALS[3][0]: 0}
    assert statuses_of(b"\x00\x00\x00\x00" + payload[4:], wanted) is None


def test_a_goal_id_that_appears_inside_another_element_is_not_mistaken_for_it() -> None:
    first = bytes(range(1, 17))
    alone = encode_goal_statuses([(first, 7, 9, 2)])
    straddling = alone[14:30]  # the end of the first id, its stamp and status: no element starts there
    assert statuses_of(alone, [straddling]) == {}
    both = encode_goal_statuses([(first, 7, 9, 2), (straddling, 0, 0, 5)])
    assert both.find(straddling) < both.rfind(straddling)  # it appears twice; only its own element counts
    assert statuses_of(both, [straddling, first]) == {straddling: 5, first: 2}
