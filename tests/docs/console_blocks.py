"""Read the runnable blocks of a markdown tutorial: console sessions and files to save.

A tutorial marks what a reader types with fenced blocks:

* ```` ```console ```` — a terminal session. A line starting with ``$ `` is a command; lines starting
  with ``> `` continue it (a here-document, as a shell prints its PS2 prompt); the other lines up to the
  next command are output the reader will see. Each output line must appear in the command's output,
  in that order, with ``...`` standing for any text; output the block leaves out is not checked.
  The info string may add words: ``background`` (the block's one command keeps running, as in a second
  terminal: it is started, its output lines are awaited, and it is stopped at the end), ``exit=N`` (the
  commands exit with status N instead of 0), ``no-test`` (interactive: shown, never run).
* ```` ```python file=PATH ```` (any language) — a file the reader saves at PATH (relative to the
  folder the commands run in at that point).

Other fenced blocks are prose and are not run.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

_FENCE = re.compile(r"^```(\S*)(.*)$")


@dataclass
class Command:
    """One command of a console block and the output lines the tutorial promises."""

    text: str
    expected: list[str] = field(default_factory=list)


@dataclass
class Step:
    """A runnable block of the tutorial, in document order.

    Attributes:
        line: the block's opening line in the markdown file (1-based), for messages.
        kind: ``"console"`` or ``"file"``.
        commands: the commands of a console block.
        background: the console block's command keeps running (stopped at the end).
        exit_code: the status every command of the console block exits with.
        path: where a file block is saved.
        content: the file block's text.
    """

    line: int
    kind: str
    commands: list[Command] = field(default_factory=list)
    background: bool = False
    exit_code: int = 0
    path: str = ""
    content: str = ""


def parse_steps(markdown: str) -> list[Step]:
    """The runnable blocks of ``markdown`` (see the module docstring for the notation).

    Raises:
        ValueError: a block is malformed (unclosed fence, output before any command, a background
            block with several commands); the message names the line.
    """
    lines = markdown.splitlines()
    steps: list[Step] = []
    index = 0
    while index < len(lines):
        match = _FENCE.match(lines[index])
        if not match:
            index += 1
            continue
        language, words = match.group(1), match.group(2).split()
        start = index + 1
        end = start
        while end < len(lines) and lines[end].rstrip() != "```":
            end += 1
        if end == len(lines):
            raise ValueError(f"line {index + 1}: the block never closes")
        body = lines[start:end]
        options = dict(word.split("=", 1) if "=" in word else (word, "") for word in words)
        if language == "console" and "no-test" not in options:
            steps.append(_console_step(index + 1, body, options))
        elif "file" in options:
            steps.append(Step(index + 1, "file", path=options["file"], content="\n".join(body) + "\n"))
        index = end + 1
    return steps


def _console_step(line: int, body: list[str], options: dict[str, str]) -> Step:
    step = Step(line, "console", background="background" in options, exit_code=int(options.get("exit", 0)))
    for number, text in enumerate(body, start=line + 1):
        if text.startswith("$ "):
            step.commands.append(Command(text[2:]))
        elif text.startswith("> ") or text == ">":
            if not step.commands:
                raise ValueError(f"line {number}: a continuation line before any command")
            step.commands[-1].text += "\n" + text[2:]
        elif text.strip():
            if not step.commands:
                raise ValueError(f"line {number}: output before any command")
            step.commands[-1].expected.append(text.strip())
    if step.background and len(step.commands) != 1:
        raise ValueError(f"line {line}: a background block holds exactly one command")
    return step


def pattern(expected: str) -> re.Pattern[str]:
    """The regular expression of one expected output line (``...`` matches any text)."""
    return re.compile(".*?".join(re.escape(part) for part in expected.split("...")))


def missing_lines(expected: list[str], output: str) -> list[str]:
    """The expected lines that do not appear in ``output`` in order (empty: all of them do)."""
    lines = [line.rstrip() for line in _strip_ansi(output).splitlines()]
    position = 0
    for number, wanted in enumerate(expected):
        regex = pattern(wanted)
        while position < len(lines) and not regex.search(lines[position]):
            position += 1
        if position == len(lines):
            return expected[number:]
        position += 1
    return []


def _strip_ansi(text: str) -> str:
    return re.sub(r"\x1b\[[0-9;]*[A-Za-z]", "", text)


def tutorial_path() -> Path:
    """``docs/tutorial.md`` of this checkout."""
    return Path(__file__).resolve().parents[2] / "docs" / "tutorial.md"
