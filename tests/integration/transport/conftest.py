"""Fixtures for transport tests: a router on a free loopback port and peer sessions joined to it."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import pytest

from kinema.transport import Session, free_endpoint, host_router, open_session


@pytest.fixture
def endpoints() -> Callable[[], str]:
    """Factory of free loopback endpoints."""
    return free_endpoint


@pytest.fixture
def router_endpoint() -> str:
    """Endpoint of this test's router."""
    return free_endpoint()


@pytest.fixture
def router(router_endpoint: str) -> Iterator[Session]:
    """A router hosted in the test process (closed afterwards)."""
    session = host_router(router_endpoint)
    yield session
    session.close()


@pytest.fixture
def connect(router: Session, router_endpoint: str) -> Iterator[Callable[[], Session]]:
    """Factory of peer sessions joined to the test's router (all closed afterwards)."""
    opened: list[Session] = []

    def open_peer() -> Session:
        session = open_session(router_endpoint)
        opened.append(session)
        return session

    yield open_peer
    for session in opened:
        session.close()
