"""A behavior package whose import never finishes is reported with its line and blocks nobody else."""

from __future__ import annotations

import queue
import time
from pathlib import Path

from kinema.plugins import BehaviorHost, ReloadKind

HANGS = "import threading\n\nthreading.Event().wait()  # waits for ever\n"
# The same, leaving a file behind once its import has started (the test waits for that, not for a guess).
HANGS_AFTER_SAYING_SO = "import pathlib\npathlib.Path({marker!r}).touch()\n" + HANGS


def test_a_hanging_import_at_start_is_reported_and_the_others_load(workspace: Path, make_package) -> None:
    make_package("stuck", classes={"Stuck": 1}, behaviors=HANGS)
    make_package("good", classes={"Good": 2})
    host = BehaviorHost(["stuck::TestLoader", "good::TestLoader"], workspace, import_time_limit=1.0)
    report = host.load()
    assert list(host.registry) == ["Good"]
    (error,) = report.errors
    assert "behavior package 'stuck' did not finish importing within 1 s" in error.message, error.message
    assert error.location is not None
    assert (Path(error.location.file).name, error.location.line) == ("behaviors.py", 3)


def test_a_package_that_starts_hanging_does_not_block_the_reload_of_another(
    workspace: Path, make_package
) -> None:
    stuck = make_package("stuck", classes={"Stuck": 1})
    good = make_package("good", classes={"Good": 2})
    host = BehaviorHost(["stuck::TestLoader", "good::TestLoader"], workspace, import_time_limit=1.0)
    assert host.load().ok
    events: queue.Queue = queue.Queue()
    host.subscribe(events.put)
    host.watch(debounce=0.05)
    try:
        marker = workspace / "stuck_import_started"
        (stuck / "stuck" / "behaviors.py").write_text(HANGS_AFTER_SAYING_SO.format(marker=str(marker)))
        deadline = time.monotonic() + 30
        while not marker.exists():  # the stuck package's change is handled first
            assert time.monotonic() < deadline, "the stuck package's reload never started"
            time.sleep(0.01)
        module = good / "good" / "behaviors.py"
        module.write_text(module.read_text().replace("2)", "3)"))
        seen = {}
        deadline = time.monotonic() + 30
        while len(seen) < 2 and time.monotonic() < deadline:
            try:
                event = events.get(timeout=1)
            except queue.Empty:
                continue
            seen[event.subject] = event
        assert set(seen) == {"stuck::TestLoader", "good::TestLoader"}, seen
    finally:
        host.stop_watching()
    assert seen["good::TestLoader"].kind is ReloadKind.BEHAVIORS_RELOADED
    failed = seen["stuck::TestLoader"]
    assert failed.kind is ReloadKind.RELOAD_FAILED and "did not finish importing" in failed.message
    assert "Stuck" in host.registry  # the last good version of the stuck package stays
