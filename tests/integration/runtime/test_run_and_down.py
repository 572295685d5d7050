"""``kinema run`` starts the agent as a child and ``kinema down`` stops everything; logs land per run."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import zipfile
from collections.abc import Iterator
from pathlib import Path

import pytest

from failure_report import describe_process, log_tail
from kinema.runtime.instance import pid_alive
from kinema.sdk import ObjectiveClient, ObjectiveStatus

READY = "objectives can be started"


@pytest.fixture
def env(tmp_path: Path, free_endpoint: str) -> dict[str, str]:
    return {
        **os.environ,
        "XDG_STATE_HOME": str(tmp_path / "state"),
        "KINEMA_ZENOH_CONNECT": free_endpoint,
        "KINEMA_CONFIG": "lab_sim",
    }


@pytest.fixture
def kinema_run(env: dict[str, str]) -> Iterator[subprocess.Popen[str]]:
    process = subprocess.Popen(
        [sys.executable, "-m", "kinema", "run", "-n", "--headless"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=env,
    )
    try:
        assert process.stdout is not None
        lines = []
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            line = process.stdout.readline()
            if not line:
                break
            lines.append(line)
            if READY in line:
                break
        assert READY in "".join(lines), "".join(lines)
        yield process
    finally:
        if process.poll() is None:
            process.send_signal(signal.SIGINT)
            try:
                process.wait(20)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait(5)


def _instance(env: dict[str, str]) -> dict[str, object]:
    records = list((Path(env["XDG_STATE_HOME"]) / "kinema" / "instances").glob("*.json"))
    assert len(records) == 1
    return json.loads(records[0].read_text())  # type: ignore[no-any-return]


def _kinema(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    argv = [sys.executable, "-m", "kinema", *args]
    return subprocess.run(argv, capture_output=True, text=True, env=env, timeout=60)


def test_run_serves_objectives_and_down_stops_every_process(
    kinema_run: subprocess.Popen[str], env: dict[str, str], tmp_path: Path
) -> None:
    record = _instance(env)
    assert record["pid"] == kinema_run.pid and record["config"] == "lab_sim"
    children = record["children"]
    assert isinstance(children, list) and len(children) == 1  # -n: the agent only
    with ObjectiveClient(env["KINEMA_ZENOH_CONNECT"], timeout=10) as client:
        assert client.status().status is ObjectiveStatus.IDLE
        assert "Look at Table" in {info.name for info in client.objectives()}

    down = _kinema(env, "down")
    assert down.returncode == 0 and f"stopped kinema run (pid {kinema_run.pid}" in down.stdout
    assert kinema_run.wait(20) == 0
    assert not any(pid_alive(int(pid)) for pid in children)
    again = _kinema(env, "down")
    assert again.returncode == 1 and "no Kinema instance is running" in again.stderr

    logs = _kinema(env, "logs")
    assert logs.returncode == 0 and "agent serving (config lab_sim" in logs.stdout
    archive = tmp_path / "logs.zip"
    exported = _kinema(env, "export-logs", "-o", str(archive))
    assert exported.returncode == 0
    with zipfile.ZipFile(archive) as zipped:
        assert {Path(name).name for name in zipped.namelist()} >= {"agent.log", "supervisor.log"}


# A killed launcher's children must be gone this soon (the lifeline's grace is 1 s), even on a busy machine.
ORPHAN_DEADLINE_S = 2.0

# Stands in for the TUI: prints the children's pids once everything started, then waits to be killed.
_SUPERVISOR = """
import sys, time
from kinema.runtime.launcher import Launcher, LaunchOptions

def ui(launcher):
    print("children", *[child.process.pid for child in launcher.children], flush=True)
    while True:
        time.sleep(1)

options = LaunchOptions(config="lab_sim", endpoint=sys.argv[1], sim_speed="max", viewer=True, ui=ui,
                        echo=lambda text: print(text, flush=True))
sys.exit(Launcher(options).run())
"""


def _describe(pids: list[int], state_home: Path) -> str:
    """What a failing orphan test saw: each child still there, and the end of every log."""
    lines = [describe_process(pid) or f"{pid:>7} gone" for pid in pids]
    lines += [f"--- {log.name}:\n{log_tail(log, 6)}" for log in sorted(state_home.rglob("*.log"))]
    return "\n".join(lines)


def _await_gone(pids: list[int], timeout: float) -> float | None:
    """Seconds until none of ``pids`` is alive, or None when some still are after ``timeout``."""
    start = time.monotonic()
    while time.monotonic() - start < timeout:
        if not any(pid_alive(pid) for pid in pids):
            return time.monotonic() - start
        time.sleep(0.02)
    return None


@pytest.fixture
def cpu_load() -> Iterator[None]:
    """Two busy processes (this machine class has 2 cores) for the length of the test."""
    burners = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(2)]
    try:
        yield
    finally:
        for burner in burners:
            burner.kill()
            burner.wait(10)


def test_killing_the_supervisor_leaves_no_orphans(
    kinema_run: subprocess.Popen[str], env: dict[str, str], cpu_load: None
) -> None:
    children = [int(pid) for pid in _instance(env)["children"]]  # type: ignore[union-attr]
    os.kill(kinema_run.pid, signal.SIGKILL)
    kinema_run.wait(10)
    took = _await_gone(children, ORPHAN_DEADLINE_S)
    assert took is not None, _describe(children, Path(env["XDG_STATE_HOME"]))
    stale = _kinema(env, "down")
    assert stale.returncode == 1  # the record of a dead supervisor is stale, not a running instance


def test_agent_driver_and_view_end_within_2_s_of_a_sigkilled_supervisor_under_load(
    env: dict[str, str], cpu_load: None
) -> None:
    supervisor = subprocess.Popen(
        [sys.executable, "-c", _SUPERVISOR, env["KINEMA_ZENOH_CONNECT"]],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**env, "BROWSER": "true"},  # the view must not try to open a real browser
    )
    try:
        assert supervisor.stdout is not None
        seen = []
        for line in supervisor.stdout:
            seen.append(line)
            if line.startswith("children"):
                break
        assert seen and seen[-1].startswith("children"), "".join(seen)
        children = [int(pid) for pid in seen[-1].split()[1:]]
        assert len(children) == 3, "".join(seen)  # the MuJoCo driver, the agent, the view
        os.kill(supervisor.pid, signal.SIGKILL)
        supervisor.wait(10)
        took = _await_gone(children, ORPHAN_DEADLINE_S)
        assert took is not None, "".join(seen) + _describe(children, Path(env["XDG_STATE_HOME"]))
    finally:
        if supervisor.poll() is None:
            supervisor.kill()
            supervisor.wait(10)


def test_ctrl_c_stops_everything_and_removes_the_record(
    kinema_run: subprocess.Popen[str], env: dict[str, str]
) -> None:
    children = [int(pid) for pid in _instance(env)["children"]]  # type: ignore[union-attr]
    kinema_run.send_signal(signal.SIGINT)
    assert kinema_run.wait(20) == 0
    assert not any(pid_alive(pid) for pid in children)
    # The terminal's last word says the runtime is gone (the ready line above it said it was running).
    assert kinema_run.stdout is not None
    assert kinema_run.stdout.read().strip().splitlines()[-1] == "Kinema stopped (config lab_sim)."
    assert not list((Path(env["XDG_STATE_HOME"]) / "kinema" / "instances").glob("*.json"))
