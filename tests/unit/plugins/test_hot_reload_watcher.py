"""The directory watcher reports one change per burst, ignores no-op events, and works by polling too."""

from __future__ import annotations

import os
import threading
from pathlib import Path

import pytest

from kinema.plugins.hot_reload import DirectoryWatcher, fingerprint


class _Recorder:
    def __init__(self) -> None:
        self.calls: list[tuple[Path, tuple[Path, ...]]] = []
        self.event = threading.Event()

    def __call__(self, folder: Path, paths: tuple[Path, ...], started: float) -> None:
        self.calls.append((folder, paths))
        self.event.set()

    def wait(self, timeout: float = 10.0) -> bool:
        found = self.event.wait(timeout)
        self.event.clear()
        return found


@pytest.fixture(params=[False, True], ids=["native", "polling"])
def polling(request: pytest.FixtureRequest) -> bool:
    return bool(request.param)


def test_a_burst_of_saves_is_reported_once(tmp_path: Path, polling: bool) -> None:
    module = tmp_path / "pkg" / "behavior.py"
    module.parent.mkdir()
    module.write_text("VALUE = 0\n")
    recorder = _Recorder()
    watcher = DirectoryWatcher(debounce=0.3, polling=polling, poll_interval=0.05)
    watcher.add(tmp_path, (".py",), recorder)
    with watcher:
        for value in range(1, 6):
            module.write_text(f"VALUE = {value}\n")
        assert recorder.wait()
        # Let any straggling events of the same burst arrive; none may cause a second report.
        assert not recorder.wait(timeout=0.8)
    assert len(recorder.calls) == 1
    assert recorder.calls[0][0] == tmp_path.resolve()


def test_temp_file_and_rename_is_one_change_to_the_real_file(tmp_path: Path) -> None:
    module = tmp_path / "behavior.py"
    module.write_text("VALUE = 0\n")
    recorder = _Recorder()
    watcher = DirectoryWatcher(debounce=0.15)
    watcher.add(tmp_path, (".py",), recorder)
    with watcher:
        temp = tmp_path / ".behavior.py.tmp1234"
        temp.write_text("VALUE = 1\n")
        os.replace(temp, module)
        assert recorder.wait()
        assert not recorder.wait(timeout=0.5)
    assert [path.name for path in recorder.calls[0][1]] == ["behavior.py"]


def test_touching_or_rewriting_the_same_content_reports_nothing(tmp_path: Path) -> None:
    module = tmp_path / "behavior.py"
    module.write_text("VALUE = 0\n")
    recorder = _Recorder()
    watcher = DirectoryWatcher(debounce=0.1)
    watcher.add(tmp_path, (".py",), recorder)
    with watcher:
        module.write_text("VALUE = 0\n")
        module.touch()
        assert not recorder.wait(timeout=0.8)


def test_files_of_other_kinds_and_editor_backups_are_ignored(tmp_path: Path) -> None:
    recorder = _Recorder()
    watcher = DirectoryWatcher(debounce=0.1)
    watcher.add(tmp_path, (".py",), recorder)
    with watcher:
        (tmp_path / "notes.txt").write_text("x")
        (tmp_path / "behavior.py~").write_text("x")
        (tmp_path / ".#behavior.py").write_text("x")
        (tmp_path / "__pycache__").mkdir()
        (tmp_path / "__pycache__" / "cached.py").write_text("x")
        assert not recorder.wait(timeout=0.6)
        (tmp_path / "new_behavior.py").write_text("x = 1\n")
        assert recorder.wait()


def test_fingerprint_changes_with_content_and_names_only(tmp_path: Path) -> None:
    (tmp_path / "a.py").write_text("1")
    first = fingerprint(tmp_path, (".py",))
    (tmp_path / "b.txt").write_text("ignored")
    assert fingerprint(tmp_path, (".py",)) == first
    (tmp_path / "a.py").write_text("2")
    assert fingerprint(tmp_path, (".py",)) != first


def test_settle_returns_once_a_save_is_reported_and_its_callback_returned(tmp_path: Path) -> None:
    """A run asks the watcher to settle first: it waits out the debounce and the reload (the callback)."""
    module = tmp_path / "behavior.py"
    module.write_text("VALUE = 0\n")
    done: list[str] = []

    def slow_reload(folder: Path, paths: tuple[Path, ...], started: float) -> None:
        threading.Event().wait(0.3)  # an import that takes a while
        done.append(module.read_text())

    watcher = DirectoryWatcher(debounce=0.1)
    watcher.add(tmp_path, (".py",), slow_reload)
    with watcher:
        assert watcher.settle(0.01)  # nothing saved: at once
        for value in (1, 2):
            module.write_text(f"VALUE = {value}\n")
            threading.Event().wait(0.05)  # the file system's notice reaches the watcher
            assert not watcher.settle(0.05)  # within the debounce, then the reload: not settled yet
            assert watcher.settle(10)
            assert done[-1] == f"VALUE = {value}\n"
    assert len(done) == 2
