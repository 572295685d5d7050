"""Instance records (what `kinema down` stops) and per-run log folders under XDG_STATE_HOME."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import pytest

from kinema.errors import KinemaError
from kinema.runtime.instance import InstanceRecord, pid_alive, running_instances, stop_all, stop_instance
from kinema.runtime.run_folder import RunFolder, list_runs, runs_dir


@pytest.fixture(autouse=True)
def state_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    return tmp_path / "state"


def test_run_folders_live_under_xdg_state_home_and_are_pruned(state_home: Path) -> None:
    first = RunFolder.create("lab_sim", keep=2)
    assert first.path.parent == state_home / "kinema" / "runs" == runs_dir()
    assert first.log_file("agent") == first.path / "agent.log"
    RunFolder.create("lab sim/odd", keep=2)
    third = RunFolder.create("lab_sim", keep=2)
    assert len(list_runs()) == 2 and not first.path.exists()
    assert RunFolder.latest() == third
    assert "lab_sim_odd" in list_runs()[0].name


def test_latest_without_runs_says_how_to_make_one() -> None:
    with pytest.raises(KinemaError, match="kinema run"):
        RunFolder.latest()


def _sleeper(ignore_term: bool = False) -> subprocess.Popen[bytes]:
    code = "import signal, time\n"
    if ignore_term:
        code += "signal.signal(signal.SIGTERM, signal.SIG_IGN)\n"
    code += "print('up', flush=True)\ntime.sleep(60)\n"
    process = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE)
    assert process.stdout is not None and process.stdout.readline().strip() == b"up"
    return process


def test_stop_sends_sigterm_and_removes_the_record() -> None:
    process = _sleeper()
    record = InstanceRecord(process.pid, "tcp/127.0.0.1:1", "/nowhere", "lab_sim")
    record.save()
    assert [r.pid for r in running_instances()] == [process.pid]
    assert stop_instance(record, timeout=5)
    process.wait(5)
    assert not record.path.exists()


def test_a_supervisor_that_ignores_sigterm_is_killed_with_its_children() -> None:
    supervisor, child = _sleeper(ignore_term=True), _sleeper()
    record = InstanceRecord(supervisor.pid, "tcp/127.0.0.1:1", "/nowhere", children=[child.pid])
    record.save()
    started = time.monotonic()
    assert not stop_instance(record, timeout=0.5)
    supervisor.wait(5)
    child.wait(5)
    assert time.monotonic() - started < 5
    assert not pid_alive(supervisor.pid) and not pid_alive(child.pid)


def test_stale_records_are_dropped_and_nothing_to_stop_is_an_error() -> None:
    process = _sleeper()
    process.kill()
    process.wait(5)
    InstanceRecord(process.pid, "tcp/127.0.0.1:1", "/nowhere").save()
    assert running_instances() == []
    with pytest.raises(KinemaError, match="no Kinema instance is running"):
        stop_all()


HUNG_SUPERVISOR = """
import signal, sys, time
from pathlib import Path
from kinema.process.log_files import configure_process_logging
configure_process_logging(Path(sys.argv[1]))
signal.signal(signal.SIGTERM, signal.SIG_IGN)
def stuck_in_shutdown():
    print("up", flush=True)
    time.sleep(60)
stuck_in_shutdown()
"""


def test_a_run_that_had_to_be_killed_first_wrote_where_it_hung_to_its_log(tmp_path: Path) -> None:
    log = tmp_path / "supervisor.log"
    process = subprocess.Popen([sys.executable, "-c", HUNG_SUPERVISOR, str(log)], stdout=subprocess.PIPE)
    assert process.stdout is not None and process.stdout.readline().strip() == b"up"
    record = InstanceRecord(process.pid, "tcp/127.0.0.1:1", str(tmp_path), "lab_sim")
    record.save()
    assert not stop_instance(record, timeout=0.3)
    process.wait(5)
    text = log.read_text()
    assert "stuck_in_shutdown" in text and "thread 0x" in text, text


def test_a_libraries_info_chatter_stays_out_of_the_run_logs_and_its_warnings_in(tmp_path: Path) -> None:
    # `kinema logs --level info` showed "No OpenGL_accelerate module loaded" from every driver.
    import logging

    from kinema.process.log_files import configure_process_logging

    log = tmp_path / "mujoco.log"
    root = logging.getLogger()
    handlers, level = list(root.handlers), root.level
    try:
        configure_process_logging(log)
        chatty = logging.getLogger("OpenGL.acceleratesupport")
        chatty.info("No OpenGL_accelerate module loaded")
        chatty.warning("a real problem")
        logging.getLogger("kinema.drivers.mujoco").info("MuJoCo driver ready")
    finally:
        for handler in list(root.handlers):
            root.removeHandler(handler)
            handler.close()
        for handler in handlers:
            root.addHandler(handler)
        root.setLevel(level)
        logging.getLogger("OpenGL.acceleratesupport").setLevel(logging.NOTSET)
        import faulthandler

        from kinema.process.log_files import STACKS_SIGNAL

        faulthandler.unregister(STACKS_SIGNAL)  # it wrote to the log file closed above
    text = log.read_text()
    assert "OpenGL_accelerate" not in text
    assert "a real problem" in text and "MuJoCo driver ready" in text
