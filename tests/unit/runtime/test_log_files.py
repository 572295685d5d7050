"""Run logs: entries from several processes merge in time order and filter by level."""

from __future__ import annotations

import logging
import threading
from pathlib import Path

import pytest

from kinema.process.log_files import follow_entries, level_number, merged_entries


def _write(path: Path, lines: list[str]) -> None:
    path.write_text("".join(line + "\n" for line in lines))


def test_entries_of_several_processes_merge_by_time_with_their_continuation_lines(tmp_path: Path) -> None:
    _write(
        tmp_path / "agent.log",
        [
            "2026-01-01 10:00:00.100 INFO    [agent] loaded 3 objectives",
            "2026-01-01 10:00:02.000 ERROR   [agent] objective failed",
            "Traceback (most recent call last):",
            "  boom",
        ],
    )
    _write(tmp_path / "mujoco.log", ["2026-01-01 10:00:01.000 WARNING [mujoco] slow step"])
    entries = merged_entries(sorted(tmp_path.glob("*.log")))
    expected = [("agent", "INFO"), ("mujoco", "WARNING"), ("agent", "ERROR")]
    assert [(e.process, e.level) for e in entries] == expected
    assert entries[-1].text.endswith("  boom")
    warnings = merged_entries(sorted(tmp_path.glob("*.log")), min_level=logging.WARNING)
    assert [e.level for e in warnings] == ["WARNING", "ERROR"]


@pytest.mark.parametrize(("name", "number"), [("warn", 30), ("WARNING", 30), ("error", 40), ("debug", 10)])
def test_level_names(name: str, number: int) -> None:
    assert level_number(name) == number


def test_an_unknown_level_lists_the_valid_ones() -> None:
    with pytest.raises(ValueError, match="debug, info, warning"):
        level_number("loud")


def test_follow_yields_only_what_is_appended_later(tmp_path: Path) -> None:
    log = tmp_path / "agent.log"
    _write(log, ["2026-01-01 10:00:00.000 INFO    [agent] old"])
    stop = threading.Event()
    seen: list[str] = []

    entries = follow_entries(tmp_path, poll_s=0.01, stop=stop)

    def consume() -> None:
        for entry in entries:
            seen.append(entry.text)
            stop.set()

    thread = threading.Thread(target=consume)
    thread.start()
    with log.open("a") as handle:
        handle.write("2026-01-01 10:00:01.000 INFO    [agent] new\n")
    thread.join(5)
    assert seen == ["2026-01-01 10:00:01.000 INFO    [agent] new"]


def test_following_a_run_that_no_longer_runs_ends(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # `kinema logs -f` followed a stopped run until Ctrl-C.
    import time

    from kinema.cli.main import main

    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path))
    run = tmp_path / "kinema" / "runs" / "20260101-100000-000001-lab_sim"
    run.mkdir(parents=True)
    _write(run / "agent.log", ["2026-01-01 10:00:00.100 INFO    [agent] loaded 3 objectives"])
    started = time.monotonic()
    assert main(["logs", "-f", "--run", run.name]) == 0
    assert time.monotonic() - started < 10
    out, err = capsys.readouterr()
    assert "loaded 3 objectives" in out and f"(run {run.name} ended)" in err
