"""Large blackboard values: never formatted whole, and never formatted on the tick thread.

A 1.9 MB attribute once spent 22 s in ``yaml.safe_dump`` from the run recorder on the tick thread: the
cancel waited, heartbeats stopped. Timings are in benchmarks/large_values.py; these tests check the
behavior (a marker instead of a dump; rendering on the worker threads).
"""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from kinema.behaviors import NodeStatus, SyncBehavior, output_port
from kinema.behaviors.context import BehaviorContext
from kinema.runtime import blackboard_text
from kinema.runtime.blackboard_text import VALUE_SIZE_CAP, render_value

BIG = "x" * 1_900_000


class PutsBigValue(SyncBehavior):
    """Writes a 1.9 MB string to its output."""

    @classmethod
    def provided_ports(cls) -> list[Any]:
        return [output_port("value", str, "{big}")]

    def tick(self) -> NodeStatus:
        self.set_output("value", BIG)
        return NodeStatus.SUCCESS


@pytest.fixture
def dumped(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """The length of the text of everything YAML is asked to dump."""
    import yaml

    sizes: list[int] = []
    real = yaml.safe_dump

    def spy(data: Any, *args: Any, **kwargs: Any) -> Any:
        text = real(data, *args, **kwargs)
        sizes.append(len(text))
        return text

    monkeypatch.setattr(yaml, "safe_dump", spy)
    return sizes


@pytest.mark.parametrize(
    ("value", "marker"),
    [
        (BIG, "<str: 1900000 characters, not shown>"),
        (b"\0" * 200_000, "<bytes: 200000 bytes, not shown>"),
        (np.zeros((500, 500)), "<ndarray: 2000000 bytes, not shown>"),
    ],
)
def test_a_value_beyond_the_cap_renders_as_its_type_and_size(
    value: Any, marker: str, dumped: list[int]
) -> None:
    assert render_value(value) == marker
    assert dumped == []


def test_large_parts_of_a_value_are_cut_before_yaml_sees_them(dumped: list[int]) -> None:
    from kinema.transport import from_dict

    message = from_dict("std_msgs/msg/String", {"data": "y" * (VALUE_SIZE_CAP - 10)})
    nested = {"note": "z" * 50_000, "items": list(range(100_000)), "map": {str(i): i for i in range(10_000)}}
    for value in (message, nested, "w" * 10_000):
        assert len(render_value(value)) <= blackboard_text.MAX_VALUE_CHARS
    assert dumped and max(dumped) < 3 * blackboard_text.MAX_VALUE_CHARS


def test_a_deeply_nested_value_renders_without_recursing_to_the_end() -> None:
    deep: list[Any] = []
    inner = deep
    for _ in range(100_000):
        inner.append([])
        inner = inner[0]
    assert render_value(deep).endswith("'...'" + "]" * 25)


def test_the_recorder_renders_on_its_worker_and_records_the_marker(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import json

    from kinema.runtime.objective_server import FactoryTreeSource, ObjectiveRequest, ObjectiveServer
    from kinema.runtime.recordings import RunRecorder, blackboard_path, list_recordings
    from kinema.testing.harness import registry_of

    threads: set[str] = set()
    real = blackboard_text.render_value

    def spy(value: Any) -> str:
        threads.add(threading.current_thread().name)
        return real(value)

    monkeypatch.setattr(blackboard_text, "render_value", spy)
    factory = registry_of([PutsBigValue]).create_factory(BehaviorContext.offline())
    xml = '<root BTCPP_format="4"><BehaviorTree ID="Big"><PutsBigValue/></BehaviorTree></root>'
    recorder = RunRecorder(tmp_path)
    with ObjectiveServer(FactoryTreeSource(factory), listeners=[recorder]) as server:
        result = server.submit(ObjectiveRequest(objective_xml=xml)).wait(30)
        assert result is not None and result.succeeded, result
    recorder.close()
    assert threads == {"kinema-recording"}
    (recording,) = list_recordings(tmp_path)
    frames = [json.loads(line) for line in blackboard_path(recording.path).read_text().splitlines()]
    assert ["Big", "big", "std::string", "<str: 1900000 characters, not shown>"] in frames[-1]["entries"]
    assert not recorder._work.running


def test_the_blackboard_stream_renders_and_publishes_on_its_worker() -> None:
    from kinema.runtime.agent import _Streams

    class Publisher:
        def __init__(self) -> None:
            self.sent: list[tuple[str, Any]] = []

        def publish(self, message: Any) -> None:
            self.sent.append((threading.current_thread().name, message))

    class FakeNode:
        def create_publisher(self, *args: Any, **kwargs: Any) -> Publisher:
            return Publisher()

    streams = _Streams(FakeNode(), None, None)  # type: ignore[arg-type]
    streams.on_blackboard("Big", [("Big", "big", "std::string", BIG)])
    streams.close()
    ((thread, message),) = streams._blackboard.sent  # type: ignore[attr-defined]
    assert thread == "kinema-blackboard"
    assert message.entries[0].value_yaml == "<str: 1900000 characters, not shown>"
    assert not streams._work.running
