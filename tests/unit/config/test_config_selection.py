from __future__ import annotations

from pathlib import Path

import pytest

from kinema.config import Workspace, active_selection, store_selection
from kinema.config.selection import selection_file
from kinema.errors import ConfigError


def test_with_nothing_selected_the_config_is_the_bundled_lab_sim(isolated_selection: Path):
    selection = active_selection()
    assert selection.workspace is None and selection.workspace_source == "unset"
    assert (selection.config, selection.config_source) == ("lab_sim", "default")
    assert selection.require_config() == "lab_sim"


def test_stored_selection_lives_in_the_xdg_config_dir(isolated_selection: Path, tmp_path: Path):
    path = store_selection(tmp_path, "lab_sim")
    assert path == isolated_selection / "kinema" / "selection.yaml" == selection_file()
    selection = active_selection()
    assert (selection.workspace, selection.config) == (tmp_path, "lab_sim")
    assert selection.config_source == "stored"


def test_environment_overrides_stored_and_flags_override_both(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
):
    store_selection(tmp_path / "stored", "stored_config")
    monkeypatch.setenv("KINEMA_WORKSPACE", str(tmp_path / "env"))
    monkeypatch.setenv("KINEMA_CONFIG", "env_config")
    selection = active_selection()
    assert (selection.workspace, selection.config) == (tmp_path / "env", "env_config")
    assert selection.workspace_source == "environment"
    selection = active_selection(tmp_path / "flag", "flag_config")
    assert (selection.workspace, selection.config) == (tmp_path / "flag", "flag_config")
    assert selection.config_source == "flag"


def test_workspace_discover_without_a_path_uses_the_active_workspace(ws, monkeypatch: pytest.MonkeyPatch):
    ws.config("robot_a")
    assert Workspace.discover().root is None  # nothing selected: bundled packages only
    monkeypatch.setenv("KINEMA_WORKSPACE", str(ws.root))
    assert Workspace.discover().has_package("robot_a")


def test_a_corrupt_stored_selection_is_a_clear_error(isolated_selection: Path):
    path = isolated_selection / "kinema" / "selection.yaml"
    path.parent.mkdir(parents=True)
    path.write_text("- not a mapping\n")
    with pytest.raises(ConfigError, match="run `kinema configure` again"):
        active_selection()
