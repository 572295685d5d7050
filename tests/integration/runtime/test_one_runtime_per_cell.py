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


SLOW_AGENT = """import sys, time
if "kinema.runtime.agent_process" in sys.orig_argv:
    time.sleep(6)  # a loaded machine: the agent announces itself after the other run has looked
"""


def test_two_runs_started_in_the_same_instant_leave_exactly_one_cell(
    env: dict[str, str], tmp_path: Path
) -> None:
    """Both used to look at the still empty network, and both started an agent and drivers on one router."""
    slow = tmp_path / "slow_agents"
    slow.mkdir()
    (slow / "sitecustomize.py").write_text(SLOW_AGENT)
    path = os.pathsep.join(p for p in (str(slow), env.get("PYTHONPATH", "")) if p)
    argv = [sys.executable, "-m", "kinema", "run", "--headless", "-n"]
    runs = [
        subprocess.Popen(
            argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env={**env, "PYTHONPATH": path}
        )
        for _ in range(2)
    ]
    try:
        # The refused one exits on its own; the other one runs until stopped.
        deadline = time.monotonic() + 120
        while all(run.poll() is None for run in runs):
            assert time.monotonic() < deadline, "neither run was refused"
            time.sleep(0.1)
        refused = next(run for run in runs if run.poll() is not None)
        running = next(run for run in runs if run is not refused)
        out, err = refused.communicate(timeout=10)
        assert refused.returncode == 1, out + err
        assert "a Kinema runtime already runs on" in err and "nothing was started" in err, err
        assert "Traceback" not in err and "Kinema is running" not in out
        assert running.poll() is None
        assert len(_agents(env["KINEMA_ZENOH_CONNECT"])) == 1
    finally:
        for run in runs:
            if run.poll() is None:
                run.send_signal(signal.SIGINT)
                try:
                    run.wait(30)
                except subprocess.TimeoutExpired:
                    run.kill()
                    run.wait(10)
