"""One runtime per cell: a second `kinema run` on a router refuses; -n and -o still split a cell; two
agents that meet anyway are reported."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from kinema_run_terminal import DRIVERS_READY, READY, Terminal

from kinema.transport import Graph, open_session


@pytest.fixture
def env(tmp_path: Path, free_endpoint: str) -> dict[str, str]:
    return {
        **os.environ,
        "XDG_STATE_HOME": str(tmp_path / "state"),
        "KINEMA_ZENOH_CONNECT": free_endpoint,
        "KINEMA_CONFIG": "lab_sim",
    }


@pytest.fixture
def agent_run(env: dict[str, str]) -> Iterator[Terminal]:
    """`kinema run -n --headless`: the agent of the cell, hosting the router."""
    terminal = Terminal(["-n", "--headless"], env)
    try:
        terminal.wait_for(READY, timeout=120)
        yield terminal
    finally:
        terminal.stop()


def _run(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "kinema", "run", "--headless", *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )


def _child(pid: int, module: str) -> int:
    """The child process of ``pid`` that runs ``module``."""
    for child in Path(f"/proc/{pid}/task/{pid}/children").read_text().split():
        if module in Path(f"/proc/{child}/cmdline").read_bytes().decode(errors="replace"):
            return int(child)
    raise AssertionError(f"no child of pid {pid} runs {module}")


def _agents(endpoint: str) -> list[str]:
    """The zenoh ids of the processes with an /objective_server node, once the graph has come in."""

    def agents(graph: Graph) -> list[str]:
        return sorted({e.zid for e in graph.entities if e.node_fqn == "/objective_server"})

    with open_session(endpoint) as session:
        cache = session.graph_cache()
        cache.wait_for(lambda graph: bool(agents(graph)), 10.0)
        time.sleep(1.0)  # a second agent's tokens would be in by now
        return agents(cache.snapshot())


def test_a_second_run_refuses_naming_the_running_instance_and_the_ways_out(
    agent_run: Terminal, env: dict[str, str]
) -> None:
    endpoint = env["KINEMA_ZENOH_CONNECT"]
    agents_before = _agents(endpoint)
    runs = Path(env["XDG_STATE_HOME"], "kinema", "runs")
    runs_before = sorted(runs.iterdir())
    second = _run(env, "-n")
    assert second.returncode == 1, second.stdout + second.stderr
    message = second.stderr
    assert f"a Kinema runtime already runs on {endpoint}" in message, message
    assert "agent of config lab_sim (pid " in message and f"started by pid {agent_run.process.pid}" in message
    assert "nothing was started" in message and "Traceback" not in message + second.stdout
    assert f"kinema ui --connect {endpoint}" in message and "kinema down" in message
    assert "Kinema is running" not in second.stdout
    assert _agents(endpoint) == agents_before and len(agents_before) == 1
    assert agent_run.process.poll() is None  # the running instance is untouched
    # The refused run leaves no log folder: `kinema logs` still shows the running instance's run.
    assert sorted(runs.iterdir()) == runs_before


def test_agent_and_drivers_started_apart_form_one_cell_and_a_full_run_is_refused(
    agent_run: Terminal, env: dict[str, str]
) -> None:
    drivers = Terminal(["-o", "--headless", "--sim-speed", "1"], env)
    try:
        drivers.wait_for(DRIVERS_READY, timeout=120)
        # A driver busy with its simulation can take seconds to answer a newly joined peer's handshake
        # (seen in CI); stopped, it answers none while the full run looks at the cell.
        driver = _child(drivers.process.pid, "kinema.drivers.mujoco")
        os.kill(driver, signal.SIGSTOP)
        try:
            full = _run(env)
        finally:
            os.kill(driver, signal.SIGCONT)
        assert full.returncode == 1, full.stdout + full.stderr
        assert "agent of config lab_sim" in full.stderr and "driver 'mujoco' of config lab_sim" in full.stderr
        again = _run(env, "-o")
        assert again.returncode == 1 and "Starting drivers here" in again.stderr, again.stderr
        assert drivers.process.poll() is None and agent_run.process.poll() is None
    finally:
        drivers.stop()


def test_two_agents_that_meet_anyway_are_reported_in_the_terminal_and_both_logs(
    agent_run: Terminal, env: dict[str, str], tmp_path: Path
) -> None:
    log_file = tmp_path / "stray-agent.log"
    stray = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "kinema.runtime.agent_process",
            "--connect",
            env["KINEMA_ZENOH_CONNECT"],
            "--no-hot-reload",
            "--log-file",
            str(log_file),
        ],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        line = agent_run.wait_for("warning: 2 agents on one network", timeout=60)
        assert f"agent (pid {stray.pid}" in line and "agent of config lab_sim" in line, line
        end = time.monotonic() + 60
        while "2 agents on one network" not in (log_file.read_text() if log_file.exists() else ""):
            assert time.monotonic() < end, log_file.read_text() if log_file.exists() else "(no log)"
            time.sleep(0.2)
    finally:
        stray.terminate()
        stray.wait(20)
