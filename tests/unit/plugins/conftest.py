"""Fixtures: behavior packages written into a temporary workspace."""

from __future__ import annotations

import textwrap
from collections.abc import Callable
from pathlib import Path

import pytest

BEHAVIOR_MODULE = '''
from kinema.behaviors import NodeStatus, SyncBehavior, output_port


class {cls}(SyncBehavior):
    """Writes {value} to ``out``."""

    @classmethod
    def provided_ports(cls):
        return [output_port("out", int, "{{out}}")]

    def tick(self):
        self.set_output("out", {value})
        return NodeStatus.SUCCESS
'''

INIT_MODULE = """
from kinema.plugins import hookimpl

from .behaviors import {classes}


@hookimpl
def register_behaviors(register):
{registers}
"""

MakePackage = Callable[..., Path]


@pytest.fixture
def workspace(tmp_path: Path) -> Path:
    (tmp_path / "ws" / "src").mkdir(parents=True)
    return tmp_path / "ws"


def write_package(
    root: Path,
    name: str,
    *,
    classes: dict[str, int] | None = None,
    init: str | None = None,
    behaviors: str | None = None,
    loader: str | None = None,
) -> Path:
    """Write behavior package ``name`` under ``root``: each class writes its value to port ``out``."""
    classes = classes if classes is not None else {"Answer": 42}
    folder = root / name
    module_dir = folder / name
    module_dir.mkdir(parents=True, exist_ok=True)
    loader = loader or f"{name}::TestLoader"
    (folder / "pyproject.toml").write_text(
        f'[project]\nname = "{name}"\nversion = "0.1.0"\n\n'
        f'[project.entry-points."kinema.behaviors"]\n"{loader}" = "{name}"\n'
    )
    if behaviors is None:
        behaviors = "".join(BEHAVIOR_MODULE.format(cls=cls, value=value) for cls, value in classes.items())
    (module_dir / "behaviors.py").write_text(textwrap.dedent(behaviors))
    if init is None:
        registers = "\n".join(f"    register({cls})" for cls in classes) or "    pass"
        init = INIT_MODULE.format(classes=", ".join(classes) or "*", registers=registers)
    (module_dir / "__init__.py").write_text(textwrap.dedent(init))
    return folder


@pytest.fixture
def make_package(workspace: Path) -> MakePackage:
    """``make_package("pkg", classes={"Answer": 42})`` writes a behavior package into the workspace."""

    def make(name: str, **kwargs: object) -> Path:
        return write_package(workspace / "src", name, **kwargs)  # type: ignore[arg-type]

    return make
