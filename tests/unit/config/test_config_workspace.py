from __future__ import annotations

from pathlib import Path

import pytest

from kinema.config import Workspace, list_config_packages
from kinema.config.workspace import CORE_OBJECTIVES_PACKAGE
from kinema.errors import ConfigError
from kinema.resources import bundled_dir


def test_workspace_sees_its_packages_and_the_bundled_ones(ws):
    ws.config("robot_a")
    nested = ws.root / "src" / "group" / "robot_b"
    ws.config("robot_b", folder="group/robot_b")
    (ws.root / "src" / "my_behaviors").mkdir()
    (ws.root / "src" / "my_behaviors" / "pyproject.toml").write_text("[project]\nname='x'\n")
    workspace = Workspace.discover(ws.root)
    assert workspace.package("robot_b").path == nested
    assert workspace.package("robot_a").origin == "workspace"
    assert workspace.package("lab_sim").origin == "bundled"
    assert workspace.package("my_behaviors").kind == "other"
    names = [p.name for p in list_config_packages(workspace)]
    assert names == sorted(names)
    assert {"robot_a", "robot_b", "lab_sim", "example_config"} <= set(names)
    assert "my_behaviors" not in names


def test_discover_from_a_folder_inside_the_workspace(ws):
    package = ws.config("robot_a")
    assert Workspace.discover(package / "config").root == ws.root.resolve()


def test_a_folder_beside_src_is_not_inside_the_workspace(ws):
    (ws.root / "notes").mkdir()
    with pytest.raises(ConfigError, match="is not a workspace"):
        Workspace.discover(ws.root / "notes")


def test_a_folder_without_src_is_not_a_workspace(tmp_path: Path):
    with pytest.raises(ConfigError, match=r"not a workspace.*kinema init"):
        Workspace.discover(tmp_path)
    with pytest.raises(ConfigError, match="does not exist"):
        Workspace.discover(tmp_path / "missing")


def test_package_name_comes_from_package_xml(ws):
    folder = ws.config("folder_name", folder="folder_name")
    (folder / "package.xml").write_text("<package format='3'><name>real_name</name></package>")
    workspace = Workspace.discover(ws.root)
    assert workspace.package("real_name").path == folder
    assert not workspace.has_package("folder_name")


@pytest.mark.parametrize("marker", ["KINEMA_IGNORE", "MOVEIT_PRO_IGNORE"])
def test_ignore_markers_hide_a_config_from_the_list_but_keep_it_usable(ws, marker: str):
    ws.config("base_config")
    (ws.root / "src" / "base_config" / marker).write_text("")
    workspace = Workspace.discover(ws.root)
    assert "base_config" not in [p.name for p in list_config_packages(workspace)]
    assert "base_config" in [p.name for p in list_config_packages(workspace, include_hidden=True)]
    assert workspace.package("base_config").hidden


def test_two_workspace_packages_with_one_name_is_an_error_naming_both_paths(ws):
    first = ws.config("twin", folder="a/twin")
    second = ws.config("twin", folder="b/twin")
    with pytest.raises(ConfigError) as caught:
        Workspace.discover(ws.root)
    assert str(first) in str(caught.value)
    assert str(second) in str(caught.value)
    assert "'twin'" in str(caught.value)


def test_a_workspace_package_overlays_a_bundled_one_with_a_notice(ws):
    overlay = ws.config("lab_sim")
    workspace = Workspace.discover(ws.root)
    assert workspace.package("lab_sim").path == overlay
    assert any("overlays the bundled one" in notice and "lab_sim" in notice for notice in workspace.notices)


def test_core_objective_library_answers_to_both_names_and_folds_moveit_pro_sub_libraries():
    workspace = Workspace.bundled_only()
    core = workspace.package(CORE_OBJECTIVES_PACKAGE)
    assert core.path == bundled_dir("objectives")
    assert workspace.package("moveit_pro_objectives") is core
    assert core.resolve_relative("objectives") == core.path
    assert core.resolve_relative(".") == core.path
    # MoveIt Pro's objectives/core, objectives/mujoco, ... all name Kinema's one core library
    assert core.resolve_relative("objectives/mujoco") == core.path
    assert core.resolve_relative("objectives/no_such_part") == core.path


def test_unknown_package_lists_the_known_ones(ws):
    ws.config("robot_a")
    workspace = Workspace.discover(ws.root)
    with pytest.raises(ConfigError, match="did you mean 'robot_a'"):
        workspace.package("robot_b")


def test_scanning_skips_build_install_and_hidden_folders(ws):
    ws.config("robot_a")
    for skipped in ("build", "install", ".git"):
        ws.config("robot_a", folder=f"{skipped}/robot_a")
    workspace = Workspace.discover(ws.root)  # no duplicate-name error
    assert workspace.package("robot_a").path == ws.root / "src" / "robot_a"
