"""NodeStatusCodes laid out directly are the bytes rosbags' serializer gives for the same message."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from observed_tree import SMALL_TREE_XML

from kinema.bt import BehaviorTreeFactory, ManualClock
from kinema.errors import TransportError
from kinema.runtime import agent, names
from kinema.runtime.node_status import NodeStatusRecorder
from kinema.runtime.node_status_cdr import NodeStatusCodesEncoder, generic_serializer
from kinema.transport.messages import _registry

REGISTRY = _registry(None)

# names of every length modulo 4 (the string's padding), empty, and not ASCII
NAMES = ["", "a", "ab", "abc", "Pick and Place", "Déplacer le bras", "名前"]


def _generic(objective_name: str, table_id: int, stamps: list[float], starts: list[int], codes: Any) -> bytes:
    """The message the agent built before it laid the bytes out itself, through rosbags."""
    codes_class = REGISTRY.message_class(names.NODE_STATUS_TYPE)
    time_class = REGISTRY.message_class("builtin_interfaces/msg/Time")
    message = codes_class(
        objective_name=objective_name,
        table_id=table_id,
        stamps=[time_class(**agent._stamp(stamp)) for stamp in stamps],
        starts=np.array(starts, dtype=np.uint32),
        codes=codes,
    )
    return REGISTRY.serialize(message, names.NODE_STATUS_TYPE)


@pytest.mark.parametrize("seed", range(6))
def test_the_encoder_gives_the_generic_serializers_bytes(seed: int) -> None:
    rng = np.random.default_rng(seed)
    encoder = NodeStatusCodesEncoder(generic_serializer(REGISTRY))
    for objective_name in NAMES:
        table_id = int(rng.integers(1, 1 << 32))
        for _ in range(3):  # the run's prefix is kept between messages
            codes = rng.integers(0, 1 << 32, size=int(rng.integers(0, 300)), dtype=np.uint32)
            count = int(rng.integers(1, 5))
            starts = sorted({0, *rng.integers(0, max(len(codes), 1), size=count - 1).tolist()})
            stamps = [float(x) for x in rng.uniform(0, 2e9, size=len(starts))]
            stamps[0] = [0.0, 1.9999999999, 1.0e9 + 0.5][seed % 3]
            assert encoder.encode(objective_name, table_id, stamps, starts, codes) == _generic(
                objective_name, table_id, stamps, starts, codes
            ), (objective_name, stamps, starts)


def test_an_encoder_that_disagrees_with_the_serializer_is_refused() -> None:
    def wrong(*args: Any) -> bytes:
        return generic_serializer(REGISTRY)(*args) + b"\x00"

    with pytest.raises(TransportError, match="does not match"):
        NodeStatusCodesEncoder(wrong)


def test_the_agent_publishes_the_bytes_of_the_generic_serializer(monkeypatch: pytest.MonkeyPatch) -> None:
    """Ticks of a tree, batches of one and several ticks, two runs, and chunks, as the agent sends them."""
    monkeypatch.setattr(agent, "NODE_STATUS_CHUNK", 7)
    payloads: list[bytes] = []

    class Publisher:
        def publish(self, message: Any) -> None:
            pass  # the node table

        def publish_raw(self, payload: bytes) -> None:
            payloads.append(payload)

    node = SimpleNamespace(create_publisher=lambda *_, **__: Publisher())
    streams = agent._Streams(node, None, SimpleNamespace())  # type: ignore[arg-type]
    clock = ManualClock(1_700_000_000.123456789)
    factory = BehaviorTreeFactory(clock=clock)
    xml = SMALL_TREE_XML
    for objective_name in ("Run one", "Deux"):
        tree = factory.create_tree_from_text(xml)
        recorder = NodeStatusRecorder()
        recorder.attach(tree)
        for ticks in (1, 3, 2):
            for _ in range(ticks):
                clock.advance(0.0007)
                tree.tick_once()
            batch = recorder.take()
            assert batch is not None
            payloads.clear()
            streams.on_node_status(objective_name, batch)
            parts = batch.split(7)
            assert len(parts) > 1
            assert payloads == [
                _generic(objective_name, batch.table.id, part.stamps, part.starts, part.code_array())
                for part in parts
            ]
        recorder.detach()
