"""The agent's zenoh shared-memory pool is 4 MiB, not zenoh's 16 MiB (all of which became resident);
a zenoh config file of the user's keeps what it says."""

from __future__ import annotations

import pytest

from kinema.runtime.agent_process import SHARED_MEMORY_POOL_BYTES, _shared_memory_pool
from kinema.transport.session import ENV_CONFIG, build_config

POOL = "transport/shared_memory/transport_optimization/pool_size"


def test_the_agent_session_gets_a_smaller_shared_memory_pool(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(ENV_CONFIG, raising=False)
    config = build_config("peer", overrides=_shared_memory_pool())
    assert int(config.get_json(POOL)) == SHARED_MEMORY_POOL_BYTES == 4 * 1024 * 1024
    assert int(build_config("peer").get_json(POOL)) > SHARED_MEMORY_POOL_BYTES  # zenoh's default


def test_a_zenoh_config_file_keeps_its_own_pool(monkeypatch: pytest.MonkeyPatch, tmp_path) -> None:
    config_file = tmp_path / "zenoh.json5"
    config_file.write_text("{transport: {shared_memory: {transport_optimization: {pool_size: 33554432}}}}")
    monkeypatch.setenv(ENV_CONFIG, str(config_file))
    assert _shared_memory_pool() == {}
    assert int(build_config("peer", overrides=_shared_memory_pool()).get_json(POOL)) == 33554432
