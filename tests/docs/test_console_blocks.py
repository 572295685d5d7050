"""The tutorial notation: what counts as a command, its output, a file, a background or skipped block."""

from __future__ import annotations

import pytest
from console_blocks import missing_lines, parse_steps

DOC = """Intro.

```console
$ kinema objective run "Close Gripper"
objective 'Close Gripper' succeeded
$ cat > a.txt <<'EOF'
> one
> EOF
```

```console background
$ kinema run --headless
Kinema is running: ... (config lab_sim, ...)
```

```console no-test
$ kinema ui
```

```python file=src/demo.py
print("hi")
```

```console exit=1
$ kinema objective run Nope
error: ...
```

```bash
echo prose only
```
"""


def test_blocks_become_steps_in_document_order() -> None:
    steps = parse_steps(DOC)
    assert [(s.kind, s.background, s.exit_code) for s in steps] == [
        ("console", False, 0),
        ("console", True, 0),
        ("file", False, 0),
        ("console", False, 1),
    ]
    first = steps[0].commands
    assert first[0].text == 'kinema objective run "Close Gripper"'
    assert first[0].expected == ["objective 'Close Gripper' succeeded"]
    assert first[1].text == "cat > a.txt <<'EOF'\none\nEOF" and first[1].expected == []
    assert steps[2].path == "src/demo.py" and steps[2].content == 'print("hi")\n'
    assert steps[1].line == 11


RUNNING = "Kinema is running: ... (config lab_sim, ...)"


@pytest.mark.parametrize(
    ("output", "missing"),
    [
        ("a\nKinema is running: yes (config lab_sim, at x)\nb\nthe end\n", []),
        ("Kinema is running: yes (config example_config, at x)\nthe end\n", [RUNNING, "the end"]),
        ("the end\nKinema is running: yes (config lab_sim, at x)\n", ["the end"]),
        ("\x1b[32mKinema is running: x (config lab_sim, y)\x1b[0m\nthe end", []),
        ("", [RUNNING, "the end"]),
    ],
)
def test_expected_lines_must_appear_in_order(output: str, missing: list[str]) -> None:
    assert missing_lines([RUNNING, "the end"], output) == missing


@pytest.mark.parametrize(
    ("doc", "words"),
    [
        ("```console\nhello\n```\n", "output before any command"),
        ("```console\n> more\n```\n", "continuation line before any command"),
        ("```console background\n$ a\n$ b\n```\n", "exactly one command"),
        ("```console\n$ a\n", "never closes"),
    ],
)
def test_malformed_blocks_are_refused_with_their_line(doc: str, words: str) -> None:
    with pytest.raises(ValueError, match=words):
        parse_steps(doc)
