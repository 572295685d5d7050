"""Shared test configuration."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

import kinema.mujoco_gl  # noqa: F401  (before any test module imports mujoco: see kinema.mujoco_gl)
from failure_report import kinema_processes
from kinema.transport import free_endpoint

REPO_ROOT = Path(__file__).resolve().parent.parent
SHARED_DIR = REPO_ROOT.parent / "shared"


@pytest.fixture(scope="session", autouse=True)
def user_folders(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """The user's config, data, state and cache folders (``XDG_*``) are the session's own.

    Tests, and the processes they start, never read a selection, waypoints or run records that the person
    running the suite (or another test run beside it) left in the real ones, and never leave theirs there.
    A test that needs folders of its own still sets them.
    """
    root = tmp_path_factory.mktemp("user")
    names = ("XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_STATE_HOME", "XDG_CACHE_HOME")
    with _environment(
        {name: str(root / name.removeprefix("XDG_").removesuffix("_HOME").lower()) for name in names}
    ):
        yield root


@pytest.fixture(scope="session", autouse=True)
def own_network() -> Iterator[str]:
    """The session's default router endpoint (``KINEMA_ZENOH_CONNECT``) is a free loopback port of its own.

    A test, or a process it starts, that does not name an endpoint would otherwise take the default
    ``tcp/127.0.0.1:7447``: join the runtime of the person running the suite, or meet a test of another
    worker (``-n``) or of another test run beside it. The user's router config (``KINEMA_ZENOH_CONFIG``)
    is left out for the same reason. Tests that need their own network still name an endpoint.
    """
    endpoint = free_endpoint()
    with _environment({"KINEMA_ZENOH_CONNECT": endpoint, "KINEMA_ZENOH_CONFIG": None}):
        yield endpoint


@contextlib.contextmanager
def _environment(values: dict[str, str | None]) -> Iterator[None]:
    """Set (a value) or unset (None) environment variables, and put the old values back afterwards."""
    saved = {name: os.environ.get(name) for name in values}
    try:
        for name, value in values.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


@pytest.fixture
def shared_dir() -> Path:
    """The ``../shared`` folder beside the checkout; tests that need it skip when it is absent."""
    if not SHARED_DIR.is_dir():
        pytest.skip(f"{SHARED_DIR} is not beside this checkout")
    return SHARED_DIR


# -- what a failing test saw ---------------------------------------------------------------------------
# A flaky failure in CI must be diagnosable from CI's output alone. Fixtures register what is worth
# showing (a log tail, positions) with ``show_on_failure(request.node, title, describe)``; a failing test
# gets those as report sections, plus the Kinema processes still running for the process-level suites.

_SHOW_ON_FAILURE = pytest.StashKey[list[tuple[str, Callable[[], str]]]]()
_PROCESS_SUITES = ("integration", "sim", "tui", "viz", "docs")


@pytest.fixture(scope="session")
def show_on_failure() -> Callable[[pytest.Item | pytest.Collector, str, Callable[[], str]], None]:
    """``show_on_failure(request.node, title, describe)``: print ``describe()`` when a test under that
    node fails (a module-scoped fixture passes its module, so every test in it shows it)."""

    def register(node: pytest.Item | pytest.Collector, title: str, describe: Callable[[], str]) -> None:
        node.stash.setdefault(_SHOW_ON_FAILURE, []).append((title, describe))

    return register


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]) -> Any:
    report = yield
    if report.failed and report.when in ("setup", "call"):
        for node in item.listchain():
            for title, describe in node.stash.get(_SHOW_ON_FAILURE, []):
                try:
                    text = describe()
                except Exception as error:  # a broken description must not hide the failure itself
                    text = f"(could not describe: {error!r})"
                report.sections.append((f"what the test saw: {title}", text))
        suite = (
            Path(item.path).relative_to(REPO_ROOT / "tests").parts[0]
            if item.path.is_relative_to(REPO_ROOT / "tests")
            else ""
        )
        if suite in _PROCESS_SUITES:
            report.sections.append(("what the test saw: Kinema processes", kinema_processes()))
    return report
