"""Fixtures for the TUI tests."""

from __future__ import annotations

import pytest

from kinema.tui.fake_connection import FakeConnection


@pytest.fixture
def fake() -> FakeConnection:
    """The demo runtime: three objectives (one a subtree), two waypoints, two behaviors."""
    return FakeConnection.demo()
