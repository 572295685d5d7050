"""Hot-reload faults show where the user looks: the `kinema run` terminal and `kinema logs`."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from kinema_run_terminal import READY, Terminal

BEHAVIOR = '''
from kinema.behaviors import NodeStatus, SyncBehavior


class Wave(SyncBehavior):
    """Succeeds."""

    @classmethod
    def provided_ports(cls):
        return []

    def tick(self):
        return NodeStatus.SUCCESS
'''

INIT = """
from kinema.plugins import hookimpl

from .behaviors import Wave


@hookimpl
def register_behaviors(register):
    register(Wave)
"""


@pytest.fixture
def workspace(tmp_path: Path) -> Path:
    """Config my_cell (based on lab_sim) loading behavior package waves from the workspace."""
    src = tmp_path / "ws" / "src"
    cell = src / "my_cell"
    (cell / "config").mkdir(parents=True)
    (cell / "objectives").mkdir()
    (cell / "package.xml").write_text("<package><name>my_cell</name></package>\n")
    (cell / "config" / "config.yaml").write_text(
        'based_on_package: "lab_sim"\n'
        "objectives:\n"
        "  behavior_loader_plugins:\n"
        '    waves: ["waves::WavesLoader"]\n'
        "  objective_library_paths:\n"
        "    my_cell_objectives: {package_name: my_cell, relative_path: objectives}\n"
    )
    package = src / "waves"
    (package / "waves").mkdir(parents=True)
    (package / "pyproject.toml").write_text(
        '[project]\nname = "waves"\nversion = "0.1.0"\n\n'
        '[project.entry-points."kinema.behaviors"]\n"waves::WavesLoader" = "waves"\n'
    )
    (package / "waves" / "__init__.py").write_text(INIT)
    (package / "waves" / "behaviors.py").write_text(BEHAVIOR)
    return tmp_path / "ws"


@pytest.fixture
def env(tmp_path: Path, free_endpoint: str) -> dict[str, str]:
    return {**os.environ, "XDG_STATE_HOME": str(tmp_path / "state"), "KINEMA_ZENOH_CONNECT": free_endpoint}


@pytest.fixture
def terminal(workspace: Path, env: dict[str, str]) -> Iterator[Terminal]:
    output = Terminal(["-n", "--headless", "-w", str(workspace), "-c", "my_cell"], env)
    try:
        output.wait_for(READY, timeout=120)
        yield output
    finally:
        output.stop()


def test_reload_errors_appear_in_the_run_terminal_and_in_kinema_logs(
    terminal: Terminal, workspace: Path, env: dict[str, str]
) -> None:
    behaviors = workspace / "src" / "waves" / "waves" / "behaviors.py"
    behaviors.write_text(BEHAVIOR.replace("def tick(self):", "def tick(self:"))
    line_no = BEHAVIOR.splitlines().index("    def tick(self):") + 1
    syntax = terminal.wait_for(f"{behaviors}:{line_no}", "waves not reloaded", "SyntaxError")
    assert syntax.startswith("agent: error:"), syntax

    behaviors.write_text("import no_such_module_anywhere\n" + BEHAVIOR)
    terminal.wait_for(f"{behaviors}:1", "ModuleNotFoundError", "no_such_module_anywhere")

    behaviors.write_text(BEHAVIOR.replace("Succeeds.", "Succeeds, again."))
    terminal.wait_for("Reloaded waves: Wave")

    broken = workspace / "src" / "my_cell" / "objectives" / "broken.xml"
    broken.write_text('<root BTCPP_format="4">\n  <BehaviorTree ID="Broken">\n    <Sequence>\n</root>\n')
    terminal.wait_for(str(broken), "objective broken.xml not reloaded")

    logs = subprocess.run(
        [sys.executable, "-m", "kinema", "logs", "--level", "error"],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )
    assert logs.returncode == 0, logs.stderr
    for needle in ("SyntaxError", "no_such_module_anywhere", "objective broken.xml not reloaded"):
        assert needle in logs.stdout, logs.stdout
    assert "Traceback" not in "".join(terminal.lines) + logs.stdout


def test_objective_run_says_when_it_runs_code_whose_latest_file_failed_to_load(
    terminal: Terminal, workspace: Path, env: dict[str, str]
) -> None:
    # A new user's edit failed to import; `objective run` failed with the previous version's exception at
    # a line that no longer held that code, and nothing said the file on disk had not loaded.
    objective = workspace / "src" / "my_cell" / "objectives" / "wave.xml"
    objective.write_text(
        '<root BTCPP_format="4">\n  <BehaviorTree ID="Wave Once">\n    <Wave/>\n  </BehaviorTree>\n</root>\n'
    )
    behaviors = workspace / "src" / "waves" / "waves" / "behaviors.py"
    behaviors.write_text(BEHAVIOR.replace("return NodeStatus.SUCCESS", "raise ValueError('old code')"))
    terminal.wait_for("Reloaded waves: Wave")
    behaviors.write_text(BEHAVIOR.replace("def tick(self):", "def tick(self:"))
    terminal.wait_for("waves not reloaded")
    line_no = BEHAVIOR.splitlines().index("    def tick(self):") + 1

    run = subprocess.run(
        [sys.executable, "-m", "kinema", "objective", "run", "Wave Once", "--timeout", "30"],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert run.returncode == 1
    said = run.stdout + run.stderr
    assert "ValueError: old code" in said
    assert f"{behaviors}:{line_no}" in said and "SyntaxError" in said, said
    assert "runs older code" in said  # said as it starts
    assert re.search(r"note: .*Wave runs the version from \d\d:\d\d instead", said), said


def test_a_wrong_port_saved_and_a_stuck_behavior_are_said_in_the_run_terminal(
    terminal: Terminal, workspace: Path, env: dict[str, str]
) -> None:
    # A new user read only "Objectives changed" for an objective saved with a wrong port, and nothing in
    # the headless terminal about a behavior stuck in tick (runtime.md says the watchdog reports there).
    objective = workspace / "src" / "my_cell" / "objectives" / "slow.xml"
    objective.write_text(
        '<root BTCPP_format="4">\n  <BehaviorTree ID="Slow Wave">\n    <Wave mass_gk="1"/>\n'
        "  </BehaviorTree>\n</root>\n"
    )
    wrong = terminal.wait_for(f"{objective}:3", "[mass_gk]")
    assert wrong.startswith("agent: warning:"), wrong
    behaviors = workspace / "src" / "waves" / "waves" / "behaviors.py"
    behaviors.write_text(
        BEHAVIOR.replace("def tick(self):", "def tick(self):\n        import time\n\n        time.sleep(2.5)")
    )
    terminal.wait_for("Reloaded waves: Wave")
    objective.write_text(objective.read_text().replace(' mass_gk="1"', ""))
    terminal.wait_for("Objectives changed: slow.xml")
    subprocess.run(
        [sys.executable, "-m", "kinema", "objective", "run", "Slow Wave", "--timeout", "30"],
        capture_output=True,
        env=env,
        timeout=120,
    )
    stuck = terminal.wait_for("watchdog: behavior 'Wave'", "has been in tick")
    assert stuck.startswith("agent: warning:"), stuck
