"""The real app against a real runtime subprocess: run an objective, watch its nodes, survive a restart.

Only built-in BT nodes are used, so no robot, simulator or behavior plugin is needed.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import socket
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from kinema.tui.app import KinemaApp
from kinema.tui.connection import ConnectionState, NodeStatus
from kinema.tui.screens.objectives import ObjectivesScreen
from kinema.tui.sdk_connection import SdkConnection
from kinema.tui.widgets.behavior_tree_view import BehaviorTreeView

pytestmark = pytest.mark.slow

COUNT_UP = """<?xml version="1.0" encoding="UTF-8"?>
<root BTCPP_format="4" main_tree_to_execute="Count Up">
  <BehaviorTree ID="Count Up" _description="Counts to three." _favorite="true">
    <Sequence name="Main">
      <Script code="count := 0"/>
      <Repeat num_cycles="3">
        <Sequence name="Step">
          <Sleep msec="300"/>
          <Script code="count += 1"/>
        </Sequence>
      </Repeat>
    </Sequence>
  </BehaviorTree>
</root>
"""


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def start_agent(endpoint: str, objectives: Path, hot_reload: bool = False) -> subprocess.Popen[bytes]:
    env = {**os.environ, "KINEMA_CONFIG": "", "KINEMA_WORKSPACE": ""}
    return subprocess.Popen(
        [
            sys.executable,
            "-m",
            "kinema.runtime.agent_process",
            "--host-router",
            endpoint,
            "--objectives",
            str(objectives),
            "--clock",
            "wall",
            *([] if hot_reload else ["--no-hot-reload"]),
        ],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )


def stop(process: subprocess.Popen[bytes]) -> None:
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(5)


class Agent:
    """An agent process on a fixed endpoint that can be stopped and started again."""

    def __init__(self, endpoint: str, objectives: Path, hot_reload: bool = False) -> None:
        self.endpoint = endpoint
        self.objectives = objectives
        self.hot_reload = hot_reload
        self.process: subprocess.Popen[bytes] | None = None

    def start(self) -> None:
        self.process = start_agent(self.endpoint, self.objectives, self.hot_reload)

    def stop(self) -> None:
        if self.process is not None:
            stop(self.process)


@pytest.fixture
def agent(tmp_path: Path) -> Iterator[Agent]:
    """A fresh agent serving the Count Up objective on a free loopback port."""
    (tmp_path / "count_up.xml").write_text(COUNT_UP)
    runner = Agent(f"tcp/127.0.0.1:{free_port()}", tmp_path)
    runner.start()
    try:
        yield runner
    finally:
        runner.stop()


async def wait_for(pilot, condition: Callable[[], bool], what: str, timeout: float = 20.0) -> None:  # type: ignore[no-untyped-def]
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        await pilot.pause(0.05)


def test_the_app_runs_an_objective_on_a_real_runtime_and_follows_a_restart(agent: Agent) -> None:
    app = KinemaApp(SdkConnection(agent.endpoint))
    seen: dict[str, set[NodeStatus]] = {}

    async def main() -> None:
        async with app.run_test(size=(140, 40)) as pilot:
            await wait_for(
                pilot, lambda: app.status.state is ConnectionState.CONNECTED, "the first heartbeat"
            )
            screen = app.screen
            assert isinstance(screen, ObjectivesScreen)
            await wait_for(
                pilot,
                lambda: screen.selected is not None and screen.selected.name == "Count Up",
                "the objective list",
            )
            view = screen.query_one(BehaviorTreeView)
            await wait_for(pilot, lambda: view.outline is not None, "the objective's tree")

            # Every status the view is given, however briefly shown: polling alone misses a 0.9 s
            # RUNNING when the event loop is starved on a busy machine.
            apply_statuses = view.apply_statuses

            def applying(updates: Any) -> int:
                updates = list(updates)
                for update in updates:
                    node = view.outline.find(update.uid, update.node_path) if view.outline else None
                    if node is not None:
                        seen.setdefault(node.path, set()).add(update.status)
                return apply_statuses(updates)

            view.apply_statuses = applying  # type: ignore[method-assign]
            await pilot.press("ctrl+r")

            def record() -> bool:
                for node in view.outline.nodes():  # type: ignore[union-attr]
                    seen.setdefault(node.path, set()).add(view.statuses.get(node.uid, NodeStatus.IDLE))
                return app.status.status == "Success" and view.status_of("Main") is NodeStatus.SUCCESS

            await wait_for(pilot, record, "the objective to succeed")
            assert NodeStatus.RUNNING in seen["Main"]
            assert NodeStatus.RUNNING in seen["Step"]
            assert view.status_of("Step") is NodeStatus.SUCCESS
            assert app.status.objective == "Count Up" and app.status.elapsed is not None
            assert app.status.elapsed >= 0.8  # three 300 ms sleeps, measured on the runtime's clock
            assert any(e.key == "count" and e.value == "3" for e in app.blackboard.entries.values())

            # The runtime goes away: shown as disconnected; it comes back: reconnected by itself.
            agent.stop()
            await wait_for(
                pilot, lambda: app.status.state is ConnectionState.DISCONNECTED, "the disconnect", 60
            )
            agent.start()
            await wait_for(pilot, lambda: app.status.state is ConnectionState.CONNECTED, "the reconnect", 30)
            await pilot.press("ctrl+r")
            await wait_for(pilot, lambda: app.status.status == "Running", "a run after the restart")

    asyncio.run(main())
    assert agent.process is not None and agent.process.poll() is None, (
        "closing an attached app stopped the runtime"
    )


def test_saved_objective_files_show_up_and_a_broken_one_is_reported_with_its_line(tmp_path: Path) -> None:
    (tmp_path / "count_up.xml").write_text(COUNT_UP)
    agent = Agent(f"tcp/127.0.0.1:{free_port()}", tmp_path, hot_reload=True)
    agent.start()
    app = KinemaApp(SdkConnection(agent.endpoint))

    async def main() -> None:
        async with app.run_test(size=(140, 40)) as pilot:
            await wait_for(
                pilot, lambda: app.status.state is ConnectionState.CONNECTED, "the first heartbeat"
            )
            screen = app.screen
            assert isinstance(screen, ObjectivesScreen)
            await wait_for(pilot, lambda: len(screen.objectives) == 1, "the objective list")

            # The runtime's watcher may still be setting up when the list first shows: a save before it
            # watches goes unseen, so the file is saved again until the list shows it.
            new = COUNT_UP.replace("Count Up", "Count Again")
            deadline = time.monotonic() + 20.0
            while len(screen.objectives) != 2:
                assert time.monotonic() < deadline, "the saved objective never showed in the list"
                (tmp_path / "count_again.xml").write_text(new)
                with contextlib.suppress(AssertionError):
                    await wait_for(pilot, lambda: len(screen.objectives) == 2, "the saved objective", 2.0)
            # The list and the reload notice come by different messages: either may arrive first.
            await wait_for(
                pilot,
                lambda: any(notice.ok and "count_again.xml" in notice.message for notice in app.reloads),
                "the reload notice of count_again.xml",
            )

            (tmp_path / "broken.xml").write_text(
                '<root BTCPP_format="4">\n  <BehaviorTree ID="B">\n    <Sequence>\n'
            )
            await wait_for(pilot, lambda: any(not n.ok for n in app.reloads), "the failed reload")
            failure = next(n for n in app.reloads if not n.ok)
            path, line = failure.location.rsplit(":", 1)
            assert path.endswith("broken.xml") and line.isdigit()

    try:
        asyncio.run(main())
    finally:
        agent.stop()


def test_the_tutorial_objective_runs_with_values_from_the_form_and_a_failure_stays_explained(
    tmp_path: Path,
) -> None:
    """example_config's "Add Numbers" (the tutorial's objective): the form lists a and b (int); with
    values it adds them; without, MyBehavior fails and the screen keeps saying why."""
    from textual.widgets import Input, OptionList, Static, TabbedContent

    from kinema.tui.widgets.override_form import OverrideForm

    endpoint = f"tcp/127.0.0.1:{free_port()}"
    env = {**os.environ, "KINEMA_CONFIG": "", "KINEMA_WORKSPACE": ""}
    argv = [sys.executable, "-m", "kinema.runtime.agent_process", "--host-router", endpoint]
    process = subprocess.Popen(
        [*argv, "--config", "example_config", "--clock", "wall", "--no-hot-reload"],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    app = KinemaApp(SdkConnection(endpoint))

    async def main() -> None:
        async with app.run_test(size=(140, 40)) as pilot:
            await wait_for(pilot, lambda: app.status.state is ConnectionState.CONNECTED, "the heartbeat", 60)
            screen = app.screen
            assert isinstance(screen, ObjectivesScreen)
            await wait_for(pilot, lambda: any(o.name == "Add Numbers" for o in screen.objectives), "the list")
            screen.query_one("#objective-search", Input).value = "Add Numbers"
            screen.query_one("#objective-list", OptionList).focus()
            await wait_for(
                pilot,
                lambda: screen.selected is not None and screen.selected.name == "Add Numbers",
                "Add Numbers selected",
            )
            screen.query_one(TabbedContent).active = "parameters"  # as a click on its tab does
            await wait_for(pilot, lambda: bool(screen.query(OverrideForm)), "the Parameters tab")
            form = screen.query_one(OverrideForm)
            await wait_for(pilot, lambda: len(form.query(Input)) == 2, "the parameter form")
            assert [(p.name, p.type_name) for p in screen.selected.ports] == [("a", "int"), ("b", "int")]
            inputs = {field.name: field for field in form.query(Input)}
            inputs["a"].value, inputs["b"].value = "40", "2"
            await pilot.press("ctrl+r")
            await wait_for(pilot, lambda: app.status.status == "Success", "Add Numbers to succeed")
            await wait_for(
                pilot,
                lambda: any(e.key == "sum" and e.value == "42" for e in app.blackboard.entries.values()),
                "sum = 42 on the blackboard",
            )

            inputs["a"].value, inputs["b"].value = "", ""
            await pilot.press("ctrl+r")
            panel = screen.query_one("#failure-panel", Static)
            await wait_for(pilot, lambda: panel.has_class("shown"), "the failure panel")
            assert "MyBehavior::2" in str(panel.render()) and "int_1" in str(panel.render())
            view = screen.query_one(BehaviorTreeView)
            await wait_for(pilot, lambda: view.shown_as("MyBehavior::2") == "FAILURE", "the failed node")
            assert view.failed_path[-1] == 2
            await pilot.pause(2.5)  # past the heartbeat's 2 s result hold: the explanation stays
            assert panel.has_class("shown") and view.shown_as("MyBehavior::2") == "FAILURE"

    try:
        asyncio.run(main())
    finally:
        stop(process)
