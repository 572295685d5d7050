"""Hot reload while running: editor-style saves of a behavior package or an objective update the registry
once, broken saves keep the last good version and report file:line."""

from __future__ import annotations

import os
import queue
import time
from pathlib import Path

import pytest

from kinema.bt import NodeStatus
from kinema.plugins import BehaviorHost, ReloadEvent, ReloadKind

SOURCE = """
from kinema.behaviors import NodeStatus, SyncBehavior, output_port


class Answer(SyncBehavior):
    @classmethod
    def provided_ports(cls):
        return [output_port("out", int, "{out}")]

    def tick(self):
        self.set_output("out", VALUE)
        return NodeStatus.SUCCESS


VALUE = 1
"""
TREE = '<root BTCPP_format="4"><BehaviorTree ID="T"><Answer out="{out}"/></BehaviorTree></root>'


def _answer(host: BehaviorHost) -> int:
    tree = host.registry.create_factory().create_tree_from_text(TREE)
    assert tree.tick_once() == NodeStatus.SUCCESS
    return tree.root_blackboard.get("out")


class _Events:
    def __init__(self, host: BehaviorHost) -> None:
        self.queue: queue.Queue[ReloadEvent] = queue.Queue()
        host.subscribe(self.queue.put)

    def next(self, timeout: float = 10.0) -> ReloadEvent:
        return self.queue.get(timeout=timeout)

    def none_within(self, seconds: float) -> bool:
        try:
            self.queue.get(timeout=seconds)
        except queue.Empty:
            return True
        return False


@pytest.fixture(params=[False, True], ids=["native", "polling"])
def watched(request: pytest.FixtureRequest, workspace: Path, write_package):
    package = write_package("answers", SOURCE, ["Answer"])
    objectives = workspace / "objectives"
    objectives.mkdir()
    (objectives / "main.xml").write_text(TREE)
    host = BehaviorHost(["answers::TestLoader"], workspace)
    assert host.load().ok
    events = _Events(host)
    host.watch([objectives], debounce=0.1, polling=request.param)
    yield host, package / "answers" / "behaviors.py", objectives, events, request.param
    host.stop_watching()


def _save(path: Path, text: str) -> None:
    path.write_text(text)


def _save_like_an_editor(path: Path, text: str) -> None:
    """Write a temp file beside it and rename it over the original (vim, VS Code, JetBrains)."""
    temp = path.with_name(f".{path.name}.swp")
    temp.write_text(text)
    os.replace(temp, path)


@pytest.mark.parametrize("save", [_save, _save_like_an_editor], ids=["in-place", "temp-and-rename"])
def test_saving_a_module_activates_the_new_class_once(watched, save) -> None:
    host, module, _objectives, events, _polling = watched
    assert _answer(host) == 1
    save(module, SOURCE.replace("VALUE = 1", "VALUE = 2"))
    event = events.next()
    assert event.kind is ReloadKind.BEHAVIORS_RELOADED
    assert event.behaviors == ("Answer",) and event.duration > 0
    assert _answer(host) == 2
    assert events.none_within(0.5)


def test_a_burst_of_saves_gives_one_reload_with_the_last_content(watched) -> None:
    host, module, objectives, events, polling = watched
    # A wider debounce window than the other tests: the burst must fit in it even on a loaded CI machine.
    host.stop_watching()
    host.watch([objectives], debounce=0.5, polling=polling)
    for value in range(2, 8):
        _save(module, SOURCE.replace("VALUE = 1", f"VALUE = {value}"))
        time.sleep(0.01)
    assert events.next().kind is ReloadKind.BEHAVIORS_RELOADED
    assert events.none_within(0.6)
    assert _answer(host) == 7


def test_a_syntax_error_keeps_the_last_good_version_and_names_the_line(watched) -> None:
    host, module, _objectives, events, _polling = watched
    broken = SOURCE.replace("def tick(self):", "def tick(self)")
    _save(module, broken)
    event = events.next()
    assert event.kind is ReloadKind.RELOAD_FAILED
    assert event.location is not None and Path(event.location.file) == module
    assert event.location.line == broken.splitlines().index("    def tick(self)") + 1
    assert "SyntaxError" in event.message
    assert _answer(host) == 1
    # Fixing the file reloads it.
    _save(module, SOURCE.replace("VALUE = 1", "VALUE = 3"))
    assert events.next().kind is ReloadKind.BEHAVIORS_RELOADED
    assert _answer(host) == 3


def test_changed_objectives_are_announced_and_broken_ones_rejected_with_the_line(watched) -> None:
    _host, _module, objectives, events, _polling = watched
    _save_like_an_editor(objectives / "main.xml", TREE.replace('ID="T"', 'ID="Renamed"'))
    event = events.next()
    assert event.kind is ReloadKind.OBJECTIVES_CHANGED
    assert [Path(path).name for path in event.paths] == ["main.xml"]
    (objectives / "main.xml").write_text('<root BTCPP_format="4">\n  <BehaviorTree ID="T">\n    <Answer\n')
    event = events.next()
    assert event.kind is ReloadKind.RELOAD_FAILED
    assert (
        event.location is not None and event.location.file.endswith("main.xml") and event.location.line >= 1
    )
