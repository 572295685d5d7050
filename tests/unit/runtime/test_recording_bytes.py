"""The run recording's transitions, packed from the status codes, are the bytes the columns gave."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from observed_tree import SMALL_TREE_XML

from kinema.bt import BehaviorTreeFactory, ManualClock
from kinema.bt.btlog import (
    TRANSITION_SIZE,
    coded_records,
    pack_coded_transitions,
    pack_transition_columns,
    read_btlog,
)
from kinema.runtime.node_status import NodeStatusBatch, NodeStatusRecorder
from kinema.runtime.recordings import RunRecorder


def _reference(batch: NodeStatusBatch, t0: float) -> bytes:
    """What the recorder wrote before it packed from the codes: the batch's columns."""
    times, uids, _previous, statuses = batch.columns()
    return pack_transition_columns(np.rint((times - t0) * 1e6), uids, statuses)


@pytest.mark.parametrize("seed", range(4))
def test_packing_codes_gives_the_bytes_of_packing_columns(seed: int) -> None:
    rng = np.random.default_rng(seed)
    # uids past 16 bits (the format keeps the low 16), every previous and new status of every node
    uids = rng.integers(0, 1 << 20, size=40).tolist()
    codes = rng.integers(0, len(uids) * 25, size=500).astype(np.uint32)
    starts = sorted({0, *rng.integers(1, len(codes), size=int(rng.integers(0, 6))).tolist()})
    # offsets before the first timestamp and past 48 bits are clamped, as the columns clamp them
    offsets = rng.choice(
        [-5, 0, 1, 123_456_789, (1 << 32) + 7, (1 << 48) - 1, 1 << 50], size=len(starts)
    ).tolist()
    counts = np.diff([*starts, len(codes)])
    columns = pack_transition_columns(
        np.repeat(np.asarray(offsets, dtype=np.int64), counts),
        np.asarray(uids, dtype=np.uint32)[codes // 25],
        codes % 5,
    )
    packed = pack_coded_transitions(coded_records(uids), codes, offsets, starts)
    assert len(packed) == TRANSITION_SIZE * len(codes)
    assert packed == columns


def _half_microsecond_steps(count: int) -> list[float]:
    """Times after 1000 s whose offsets are exact half microseconds (where rounding rules differ)."""
    # k / 2**20 s is k * 15625 / 2**14 us: a half when k * 15625 % 2**14 == 2**13, and from one such k
    # to the next (+ 2**14) the whole part grows by 15625, so halves round down and up in turn
    first = next(k for k in range(1 << 14) if k * 15625 % (1 << 14) == 1 << 13)
    return [(first + i * (1 << 14)) / 2**20 for i in range(count)]


def test_the_recorder_writes_the_bytes_the_columns_gave(tmp_path: Path) -> None:
    clock = ManualClock(1000.0)
    factory = BehaviorTreeFactory(clock=clock)
    xml = SMALL_TREE_XML
    recording = RunRecorder(tmp_path)
    expected = b""
    half_steps = iter(_half_microsecond_steps(40))
    for run in range(2):  # a second run, with another tree, gets its own records
        tree = factory.create_tree_from_text(
            xml if run == 0 else xml.replace("<Sequence>", "<Sequence><AlwaysSuccess/>")
        )
        recorder = NodeStatusRecorder()
        recorder.attach(tree)
        recording.on_tree_loaded("Demo", tree)
        t0 = clock.now()
        for ticks in (1, 3, 2, 1):  # batches of one and of several root ticks
            for _ in range(ticks):
                clock.set_time(t0 + next(half_steps))
                tree.tick_once()
            batch = recorder.take()
            assert batch is not None and len(batch.stamps) == ticks
            recording.on_node_status("Demo", batch)
            expected += _reference(batch, t0)
        path = recording.current
        assert path is not None
        recording.close()
        written = path.read_bytes()
        assert written.endswith(expected) and len(read_btlog(path).transitions) * TRANSITION_SIZE == len(
            expected
        )
        expected = b""
        clock.advance(1.0)
