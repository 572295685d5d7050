"""Fixtures: an agent process on a free loopback port, serving objectives made of BT.CPP built-ins."""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from failure_report import log_tail
from kinema.transport import free_endpoint

OBJECTIVES = """<root BTCPP_format="4">
  <BehaviorTree ID="Quick">
    <Sequence><Script code="answer := 42"/></Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Forever">
    <KeepRunningUntilFailure><Sleep msec="20"/></KeepRunningUntilFailure>
  </BehaviorTree>
  <BehaviorTree ID="Short Sleep">
    <Sequence><Sleep msec="200"/></Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Fails">
    <Sequence name="main"><AlwaysSuccess/><AlwaysFailure name="broken"/></Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Typed">
    <Sequence>
      <Sleep msec="{delay}"/>
      <SetBlackboard value="{greeting}" output_key="echo"/>
    </Sequence>
  </BehaviorTree>
</root>
"""


@dataclass
class AgentProcess:
    """A running agent: its router endpoint and process."""

    endpoint: str
    process: subprocess.Popen[bytes]
    log_file: Path


def start_agent(tmp_path: Path, *extra: str, hot_reload: bool = False) -> AgentProcess:
    """Start ``python -m kinema.runtime.agent_process`` hosting a router on a free port; wait until ready."""
    folder = tmp_path / "objectives"
    folder.mkdir(exist_ok=True)
    (folder / "builtins.xml").write_text(OBJECTIVES)
    endpoint = free_endpoint()
    log_file = tmp_path / "agent.log"
    read_fd, write_fd = os.pipe()
    argv = [
        sys.executable,
        "-m",
        "kinema.runtime.agent_process",
        "--host-router",
        endpoint,
        "--objectives",
        str(folder),
        *([] if hot_reload else ["--no-hot-reload"]),
        "--log-file",
        str(log_file),
        "--ready-fd",
        str(write_fd),
        *extra,
    ]
    process = subprocess.Popen(argv, pass_fds=(write_fd,), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    os.close(write_fd)
    with os.fdopen(read_fd) as ready:
        line = ready.readline().strip()
    if line != "ready":
        process.kill()
        _, err = process.communicate(timeout=10)
        log = log_file.read_text() if log_file.exists() else ""
        raise RuntimeError(f"agent did not start: {err.decode()}\n{log}")
    return AgentProcess(endpoint, process, log_file)


def stop_agent(agent: AgentProcess) -> None:
    """SIGTERM the agent and wait; kill it if it hangs."""
    agent.process.terminate()
    try:
        agent.process.wait(10)
    except subprocess.TimeoutExpired:
        agent.process.kill()
        agent.process.wait(5)


@contextlib.contextmanager
def running_agent(
    request: pytest.FixtureRequest, tmp_path: Path, *extra: str, hot_reload: bool = False
) -> Iterator[AgentProcess]:
    """An agent for the life of a fixture; a failing test under it shows the end of the agent's log."""
    running = start_agent(tmp_path, *extra, hot_reload=hot_reload)
    request.getfixturevalue("show_on_failure")(
        request.node, "the agent's log", lambda: log_tail(running.log_file)
    )
    try:
        yield running
    finally:
        stop_agent(running)


@pytest.fixture(scope="module")
def agent(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Iterator[AgentProcess]:
    """One agent per test module: every test starts from whatever the previous one left running, which
    is itself part of what is tested (the server keeps serving)."""
    with running_agent(request, tmp_path_factory.mktemp("agent")) as running:
        yield running


@pytest.fixture
def fresh_agent(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[AgentProcess]:
    """An agent of the test's own (the test may kill or stop it)."""
    with running_agent(request, tmp_path) as running:
        yield running


@pytest.fixture
def client(agent: AgentProcess) -> Iterator[object]:
    from kinema.sdk import ObjectiveClient

    with ObjectiveClient(agent.endpoint, timeout=10) as connected:
        yield connected


@pytest.fixture(name="free_endpoint")
def free_endpoint_fixture() -> str:
    """A loopback endpoint nothing listens on."""
    return free_endpoint()


@pytest.fixture
def sim_agent(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[AgentProcess]:
    """An agent whose clock follows /clock (as with a simulator), with nothing publishing it yet."""
    with running_agent(request, tmp_path, "--clock", "sim") as running:
        yield running


@pytest.fixture
def lively_agent(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[AgentProcess]:
    """An agent with hot reload on and a waypoints file of its own (``tmp_path/waypoints.yaml``)."""
    waypoints = str(tmp_path / "waypoints.yaml")
    with running_agent(request, tmp_path, "--waypoints", waypoints, hot_reload=True) as running:
        yield running


@pytest.fixture
def lab_sim_agent(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[AgentProcess]:
    """An agent for the bundled lab_sim config (its behaviors, wall time, no driver)."""
    with running_agent(request, tmp_path, "--config", "lab_sim", "--clock", "wall") as running:
        yield running


@pytest.fixture(params=[False], ids=[""])
def derived_config_agent(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[AgentProcess]:
    """An agent for config ``my_cell`` (based on the bundled lab_sim) of a workspace at ``tmp_path/ws``
    (watching its files when parametrized ``indirect`` with True)."""
    package = tmp_path / "ws" / "src" / "my_cell"
    (package / "config").mkdir(parents=True)
    (package / "config" / "config.yaml").write_text('based_on_package: "lab_sim"\n')
    (package / "package.xml").write_text("<package><name>my_cell</name></package>\n")
    workspace = str(tmp_path / "ws")
    with running_agent(
        request,
        tmp_path,
        "--config",
        "my_cell",
        "--workspace",
        workspace,
        "--clock",
        "wall",
        hot_reload=request.param,
    ) as running:
        yield running


@pytest.fixture
def own_agent(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[AgentProcess]:
    """An agent no other test has used (for measuring the process itself)."""
    with running_agent(request, tmp_path) as running:
        yield running
