"""`kinema objective list/show` describe the config the runtime on this machine runs (`kinema run -c NAME`)
when nothing else chooses one."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from kinema.cli.main import main
from kinema.runtime.instance import InstanceRecord


@pytest.fixture
def own_folders(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    for name in ("XDG_STATE_HOME", "XDG_CONFIG_HOME", "XDG_DATA_HOME"):
        monkeypatch.setenv(name, str(tmp_path / name.lower()))
    for name in ("KINEMA_CONFIG", "KINEMA_WORKSPACE"):
        monkeypatch.delenv(name, raising=False)
    return tmp_path


def test_objective_show_reads_the_config_that_the_running_runtime_runs(
    own_folders: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # Nothing runs: the selected config (lab_sim, the default) has no "Add Numbers".
    assert main(["objective", "show", "Add Numbers"]) != 0
    assert "no objective named 'Add Numbers'" in capsys.readouterr().err
    # `kinema run -c example_config` on the router the verbs join (this process stands for it).
    record = InstanceRecord(
        os.getpid(), os.environ["KINEMA_ZENOH_CONNECT"], str(own_folders), "example_config"
    )
    record.save()
    try:
        assert main(["objective", "show", "Add Numbers"]) == 0
        shown = capsys.readouterr()
        assert "package:     example_config" in shown.out
        assert (
            "config example_config: what the runtime at" in shown.err
            and "selected config is lab_sim" in shown.err
        )
        assert main(["objective", "list"]) == 0
        assert "Add Numbers" in capsys.readouterr().out
        # What the user chooses still wins: -c, or KINEMA_CONFIG.
        assert main(["objective", "show", "Add Numbers", "-c", "lab_sim"]) != 0
        capsys.readouterr()
        monkeypatch.setenv("KINEMA_CONFIG", "lab_sim")
        assert main(["objective", "show", "Add Numbers"]) != 0
        assert "what the runtime" not in capsys.readouterr().err
    finally:
        record.remove()


def test_a_runtime_on_another_router_does_not_change_the_selection(
    own_folders: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    record = InstanceRecord(os.getpid(), "tcp/127.0.0.1:1", str(own_folders), "example_config")
    record.save()
    try:
        assert main(["objective", "show", "Add Numbers"]) != 0
        assert "what the runtime" not in capsys.readouterr().err
    finally:
        record.remove()
