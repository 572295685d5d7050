"""The behavior packages of a workspace and the Python dependencies they declare.

``kinema build`` installs what a package's ``pyproject.toml`` lists under ``[project] dependencies``
into Kinema's own environment. The package itself is not installed: the runtime loads it from its
folder, which is what lets it hot-reload. Requirements that are already satisfied are skipped, so a
build with nothing new to install needs no network.
"""

from __future__ import annotations

import subprocess
import sys
import tomllib
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

from kinema.errors import KinemaError, PluginError, SourceLocation, did_you_mean
from kinema.plugins.discovery import ENTRY_POINT_GROUP


@dataclass(frozen=True)
class BehaviorPackage:
    """A workspace package with a ``kinema.behaviors`` entry point.

    Attributes:
        name: the package (folder) name.
        path: the package folder.
        dependencies: the requirement strings of ``[project] dependencies``.
    """

    name: str
    path: Path
    dependencies: tuple[str, ...]

    @property
    def has_tests(self) -> bool:
        """True when the package has a ``tests/`` (or ``test/``) folder."""
        return (self.path / "tests").is_dir() or (self.path / "test").is_dir()


def workspace_behavior_packages(workspace: Path, selected: Iterable[str] = ()) -> list[BehaviorPackage]:
    """The behavior packages of ``workspace`` (all, or the ``selected`` names), sorted by name.

    Raises:
        PluginError: a selected name is not a behavior package (the message lists the valid ones), or a
            ``pyproject.toml`` does not parse.
    """
    from kinema.config import Workspace

    found: dict[str, BehaviorPackage] = {}
    for package in Workspace.discover(workspace).packages.values():
        pyproject = package.path / "pyproject.toml"
        if package.origin != "workspace" or not pyproject.is_file():
            continue
        try:
            data = tomllib.loads(pyproject.read_text(encoding="utf-8"))
        except tomllib.TOMLDecodeError as error:
            raise PluginError(f"cannot parse it: {error}", location=SourceLocation(str(pyproject))) from None
        project = data.get("project", {})
        if not project.get("entry-points", {}).get(ENTRY_POINT_GROUP):
            continue
        found[package.name] = BehaviorPackage(
            package.name, package.path, tuple(str(d) for d in project.get("dependencies", []))
        )
    chosen = list(selected)
    for name in chosen:
        if name not in found:
            raise PluginError(
                f"no behavior package named '{name}' in {workspace}; {did_you_mean(name, found)}"
            )
    names = chosen or sorted(found)
    return [found[name] for name in sorted(set(names))]


def unsatisfied(requirements: Iterable[str]) -> list[str]:
    """The requirements the current environment does not satisfy (name missing or version outside)."""
    from packaging.requirements import InvalidRequirement, Requirement

    missing = []
    for text in requirements:
        try:
            requirement = Requirement(text)
        except InvalidRequirement as error:
            raise KinemaError(f"invalid requirement {text!r}: {error}") from None
        if requirement.marker is not None and not requirement.marker.evaluate():
            continue
        try:
            installed = metadata.version(requirement.name)
        except metadata.PackageNotFoundError:
            missing.append(text)
            continue
        if requirement.specifier and not requirement.specifier.contains(installed, prereleases=True):
            missing.append(text)
    return missing


def pip_install(requirements: list[str], echo: Callable[[str], None]) -> None:
    """``pip install`` ``requirements`` into this environment, echoing pip's output line by line.

    Raises:
        KinemaError: pip failed (its last lines are in the message).
    """
    command = [sys.executable, "-m", "pip", "install", "--disable-pip-version-check", *requirements]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    tail: list[str] = []
    assert process.stdout is not None
    for line in process.stdout:
        line = line.rstrip()
        echo(line)
        tail = [*tail[-9:], line]
    if process.wait() != 0:
        raise KinemaError(f"pip could not install {', '.join(requirements)}:\n" + "\n".join(tail))
