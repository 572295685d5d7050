"""A crashed agent is started again by ``kinema run`` (a bounded number of times, each said), and the
driver stops the motion the dead agent left running and holds the robot still meanwhile."""

from __future__ import annotations

import os
import queue
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from kinema.runtime.launcher import AGENT_RESTARTS

READY = "objectives can be started"


class KinemaRun:
    """`kinema run --headless` (agent and drivers), its output read by a thread, stopped at the end."""

    def __init__(self, env: dict[str, str]) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "kinema", "run", "--headless"],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env=env,
        )
        self.lines: queue.Queue[str] = queue.Queue()
        self.seen: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self.lines.put(line)

    def wait_for(self, text: str, timeout: float = 120) -> str:
        deadline = time.monotonic() + timeout
        while True:
            try:
                line = self.lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                raise AssertionError(f"never printed {text!r}:\n{''.join(self.seen)}") from None
            self.seen.append(line)
            if text in line:
                return line

    def agent_pid(self) -> int:
        pid = self.process.pid
        children = Path(f"/proc/{pid}/task/{pid}/children").read_text().split()
        for child in children:
            if "kinema.runtime.agent_process" in Path(f"/proc/{child}/cmdline").read_text():
                return int(child)
        raise AssertionError(f"no agent among the children {children}")

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
            try:
                self.process.wait(30)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(10)


@pytest.fixture
def cell(tmp_path: Path, free_endpoint: str) -> Iterator[KinemaRun]:
    env = {
        **os.environ,
        "XDG_STATE_HOME": str(tmp_path / "state"),
        "KINEMA_ZENOH_CONNECT": free_endpoint,
        "KINEMA_CONFIG": "lab_sim",
    }
    run = KinemaRun(env)
    try:
        run.wait_for(READY)
        yield run
    finally:
        run.stop()


def _speed(message: Any) -> float:
    return max((abs(v) for v in message.velocity), default=0.0)


def test_a_killed_agent_is_restarted_and_the_driver_holds_the_robot_still(
    cell: KinemaRun, free_endpoint: str, tmp_path: Path
) -> None:
    from kinema.sdk import ObjectiveClient, QuickClient
    from kinema.transport import Node

    states: queue.Queue[Any] = queue.Queue()
    with ObjectiveClient(free_endpoint, timeout=20) as client:
        Node(client.session, "watch").create_subscription(
            "sensor_msgs/msg/JointState", "/joint_states", states.put
        )
        with QuickClient(free_endpoint, timeout=20) as quick:
            quick.start("3 Waypoints Pick and Place")
            deadline = time.monotonic() + 120
            while _speed(states.get(timeout=10)) < 0.3:  # the arm moves, mid-motion
                assert time.monotonic() < deadline, "the arm never moved"
        os.kill(cell.agent_pid(), signal.SIGKILL)
        said = cell.wait_for("restarting it")
        assert "agent exited unexpectedly (code -9)" in said and f"(1 of {AGENT_RESTARTS})" in said, said
        cell.wait_for("agent restarted")
        # The goal the dead agent left is stopped: the arm comes to rest and stays there.
        deadline = time.monotonic() + 20
        while True:
            message = states.get(timeout=10)
            if _speed(message) < 1e-3:
                break
            assert time.monotonic() < deadline, f"the arm still moves: {list(message.velocity)}"
        while not states.empty():
            states.get_nowait()
        time.sleep(0.5)
        later = states.get(timeout=10)
        moved = max(abs(a - b) for a, b in zip(message.position, later.position, strict=True))
        assert moved < 0.01, f"the arm drifted {moved:.3f} rad while no agent commanded it"
        assert client.execute("Close Gripper", timeout=60).succeeded
    logs = {path.name: path.read_text() for path in (tmp_path / "state").glob("kinema/runs/*/*.log")}
    assert "restarting it (1 of" in logs["supervisor.log"], sorted(logs)
    driver = next(text for name, text in logs.items() if name not in ("supervisor.log", "agent.log"))
    assert "went away with 1 goal(s) running: stopping them and holding the robot still" in driver


def test_a_driver_killed_mid_motion_fails_the_objective_naming_it_never_preempted(
    cell: KinemaRun, free_endpoint: str
) -> None:
    """The probe: a driver killed mid-motion ended the objective PREEMPTED (-7)."""
    from kinema.runtime.error_codes import MoveItErrorCode
    from kinema.sdk import ObjectiveClient, QuickClient
    from kinema.transport import Node

    states: queue.Queue[Any] = queue.Queue()
    with (
        ObjectiveClient(free_endpoint, timeout=20) as client,
        QuickClient(free_endpoint, timeout=20) as quick,
    ):
        Node(client.session, "watch").create_subscription(
            "sensor_msgs/msg/JointState", "/joint_states", states.put
        )
        run = quick.start("3 Waypoints Pick and Place")
        deadline = time.monotonic() + 120
        while _speed(states.get(timeout=10)) < 0.3:  # the arm moves, mid-motion
            assert time.monotonic() < deadline, "the arm never moved"
        pid = cell.process.pid
        children = Path(f"/proc/{pid}/task/{pid}/children").read_text().split()
        driver = next(c for c in children if "kinema.drivers" in Path(f"/proc/{c}/cmdline").read_text())
        os.kill(int(driver), signal.SIGKILL)
        result = run.result()
    assert result.error_code != MoveItErrorCode.PREEMPTED, result
    assert result.error_code == MoveItErrorCode.FAILURE and "driver 'mujoco'" in result.error_message, result
