"""Fixtures: a workspace, a behavior package written into it, an in-process transport node."""

from __future__ import annotations

import textwrap
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest


@pytest.fixture
def workspace(tmp_path: Path) -> Path:
    (tmp_path / "ws" / "src").mkdir(parents=True)
    return tmp_path / "ws"


@pytest.fixture
def write_package(workspace: Path) -> Callable[[str, str, list[str]], Path]:
    """``write_package(name, module_source, ["ClassA", ...])``: a package registering those classes."""

    def write(name: str, source: str, classes: list[str]) -> Path:
        folder = workspace / "src" / name
        (folder / name).mkdir(parents=True, exist_ok=True)
        (folder / "pyproject.toml").write_text(
            f'[project]\nname = "{name}"\nversion = "0.1.0"\n'
            f'[project.entry-points."kinema.behaviors"]\n"{name}::TestLoader" = "{name}"\n'
        )
        (folder / name / "behaviors.py").write_text(textwrap.dedent(source).lstrip())
        registers = "".join(f"    register({cls})\n" for cls in classes)
        (folder / name / "__init__.py").write_text(
            "from kinema.plugins import hookimpl\n"
            f"from .behaviors import {', '.join(classes)}\n\n\n"
            "@hookimpl\ndef register_behaviors(register):\n" + registers
        )
        return folder

    return write


@pytest.fixture
def node() -> Iterator[Any]:
    """A transport node on a private in-process network."""
    from kinema.transport import Node, open_session

    session = open_session([])
    try:
        yield Node(session, "behavior_tests")
    finally:
        session.close()
