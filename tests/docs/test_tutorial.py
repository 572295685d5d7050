"""docs/tutorial.md, run as a reader would: every console block, in order, in a fresh folder.

The commands run through bash in a temporary folder with their own XDG_CONFIG_HOME / XDG_STATE_HOME
(so `kinema configure` and the run logs stay there) and a free loopback port (KINEMA_ZENOH_CONNECT), with
this Python's `kinema` first on PATH. The only liberty taken with the text: `kinema run` gets
`--sim-speed max`, so the simulated robot moves as fast as the CPU allows. `cd DIR` changes the folder the
next commands run in. Background blocks are started in a process group of their own and stopped (SIGINT,
as the reader's Ctrl-C, then SIGKILL) at the end, after `kinema down` has stopped any runtime left.
"""

from __future__ import annotations

import os
import re
import shlex
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
from console_blocks import Step, missing_lines, parse_steps, tutorial_path

from failure_report import log_tail
from kinema.transport import free_endpoint

COMMAND_TIMEOUT_S = 180.0
BACKGROUND_READY_S = 120.0


def _faster(command: str) -> str:
    """`kinema run ...` (not `--list`/`--help`) with the simulation as fast as the CPU allows."""
    words = command.split()
    if words[:2] == ["kinema", "run"] and not {"--list", "-l", "--help", "-h"} & set(words):
        return command + " --sim-speed max"
    return command


class Reader:
    """Types the tutorial's commands into a fresh environment and keeps what they print."""

    def __init__(self, home: Path, document: str = "tutorial") -> None:
        self.document = document
        self.cwd = home
        bin_dir = str(Path(sys.executable).parent)
        self.env = {
            **os.environ,
            "PATH": bin_dir + os.pathsep + os.environ.get("PATH", ""),
            "HOME": str(home),
            "XDG_CONFIG_HOME": str(home / ".config"),
            "XDG_STATE_HOME": str(home / ".state"),
            "KINEMA_ZENOH_CONNECT": free_endpoint(),
            "PYTHONUNBUFFERED": "1",
            "NO_COLOR": "1",
        }
        for variable in ("KINEMA_WORKSPACE", "KINEMA_CONFIG"):
            self.env.pop(variable, None)
        self.background: list[tuple[subprocess.Popen[bytes], Path]] = []
        self.outputs: list[tuple[str, str]] = []  # (command, what it printed), in order

    def save(self, step: Step) -> None:
        path = self.cwd / step.path
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(step.content, encoding="utf-8")

    def run(self, step: Step) -> None:
        for command in step.commands:
            text = command.text.strip()
            if re.fullmatch(r"cd \S+", text):
                self.cwd = (self.cwd / text[3:]).resolve()
                continue
            if step.background:
                output = self._start_background(step, text)
            else:
                output = self._run_one(step, text)
            self.outputs.append((text, output))
            missing = missing_lines(command.expected, output)
            assert not missing, (
                f"{self.document} line {step.line}: `{text}` did not print {missing[0]!r}; "
                f"it printed:\n{output}"
            )

    def _run_one(self, step: Step, text: str) -> str:
        try:
            result = subprocess.run(
                ["bash", "-c", _faster(text)],
                cwd=self.cwd,
                env=self.env,
                stdin=subprocess.DEVNULL,
                capture_output=True,
                timeout=COMMAND_TIMEOUT_S,
            )
        except subprocess.TimeoutExpired as error:
            raise AssertionError(f"tutorial line {step.line}: `{text}` did not finish") from error
        output = result.stdout.decode(errors="replace") + result.stderr.decode(errors="replace")
        assert result.returncode == step.exit_code, (
            f"tutorial line {step.line}: `{text}` exited with {result.returncode}, "
            f"not {step.exit_code}:\n{output}"
        )
        return output

    def _start_background(self, step: Step, text: str) -> str:
        log = self.cwd / f".background-{len(self.background)}.log"
        with open(log, "wb") as sink:
            process = subprocess.Popen(
                ["bash", "-c", "exec " + _faster(text)],
                cwd=self.cwd,
                env=self.env,
                stdin=subprocess.DEVNULL,
                stdout=sink,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        self.background.append((process, log))
        expected = step.commands[0].expected
        deadline = time.monotonic() + BACKGROUND_READY_S
        while True:
            output = log.read_text(errors="replace")
            if not missing_lines(expected, output):
                return output
            if process.poll() is not None or time.monotonic() > deadline:
                return output  # the caller reports what is missing, with this output

    def follow(self, steps: list[Step]) -> None:
        """Save every file and type every command of ``steps`` in order; stop what runs at the end."""
        try:
            for step in steps:
                if step.kind == "file":
                    self.save(step)
                else:
                    self.run(step)
        finally:
            self.stop_everything()

    def stop_everything(self) -> None:
        """`kinema down` for runtimes, then Ctrl-C (SIGINT) and SIGKILL for every background command."""
        subprocess.run(
            ["kinema", "down"], cwd=self.cwd, env=self.env, capture_output=True, timeout=60, check=False
        )
        for process, _ in self.background:
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGINT)
        for process, _ in self.background:
            try:
                process.wait(10)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait(5)


def _run_logs(home: Path) -> str:
    """The end of every log the tutorial's runtimes wrote (``kinema run`` keeps them per run)."""
    logs = sorted((home / ".state" / "kinema" / "runs").glob("*/*.log"), key=lambda p: p.stat().st_mtime)
    return "\n".join(f"--- {log.parent.name}/{log.name}\n{log_tail(log, 25)}" for log in logs) or "(none)"


def test_the_tutorial_parses_into_commands_and_files() -> None:
    steps = parse_steps(tutorial_path().read_text(encoding="utf-8"))
    commands = [shlex.split(c.text.split("\n")[0])[:2] for s in steps for c in s.commands]
    assert ["kinema", "init"] in commands and ["kinema", "run"] in commands
    assert any(step.background for step in steps)
    assert any(step.kind == "file" for step in steps)


def test_every_verb_of_the_command_line_appears_in_the_tutorial() -> None:
    from kinema.cli.main import VERBS

    text = tutorial_path().read_text(encoding="utf-8")
    shown = {verb for verb in VERBS if re.search(rf"(`|\$ )kinema {re.escape(verb)}\b", text)}
    missing = sorted(set(VERBS) - shown)
    assert not missing, f"docs/tutorial.md never shows: {', '.join(missing)}"


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_every_command_of_the_tutorial_prints_what_the_tutorial_says(
    tmp_path: Path, request: pytest.FixtureRequest, show_on_failure: Any
) -> None:
    steps = parse_steps(tutorial_path().read_text(encoding="utf-8"))
    reader = Reader(tmp_path)
    show_on_failure(request.node, "the runtimes' logs", lambda: _run_logs(tmp_path))
    reader.follow(steps)
    leftover = [process.pid for process, _ in reader.background if process.poll() is None]
    assert not leftover, f"background commands still running: {leftover}"
