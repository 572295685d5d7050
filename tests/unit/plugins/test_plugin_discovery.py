"""Which plugins exist and which loader names a config activates."""

from __future__ import annotations

from pathlib import Path

import pytest

from kinema.errors import PluginError
from kinema.plugins.discovery import (
    PluginSource,
    available_plugins,
    default_loader_name,
    read_behavior_package,
    select_loaders,
)


@pytest.mark.parametrize(
    ("package", "loader"),
    [
        ("my_pkg", "my_pkg::MyPkgBehaviorsLoader"),
        ("lab_sim_behaviors", "lab_sim_behaviors::LabSimBehaviorsLoader"),
        ("my_service_client", "my_service_client::MyServiceClientBehaviorsLoader"),
        ("behaviors", "behaviors::BehaviorsBehaviorsLoader"),
    ],
)
def test_default_loader_names_follow_moveit_pro_naming(package: str, loader: str) -> None:
    assert default_loader_name(package) == loader


def test_the_bundled_loaders_are_available() -> None:
    catalog, errors = available_plugins()
    assert errors == []
    for name in (
        "kinema::CoreBehaviorsLoader",
        "kinema::MujocoBehaviorsLoader",
        "kinema::ExampleBehaviorsLoader",
    ):
        assert catalog[name].source is PluginSource.BUNDLED


def test_moveit_pro_loader_names_select_the_kinema_equivalents() -> None:
    catalog, _ = available_plugins()
    selection = select_loaders(
        ["moveit_pro::behaviors::CoreBehaviorsLoader", "moveit_pro::behaviors::MujocoBehaviorsLoader"],
        catalog,
    )
    assert [spec.name for spec in selection.plugins] == [
        "kinema::CoreBehaviorsLoader",
        "kinema::MujocoBehaviorsLoader",
    ]
    assert selection.warnings == () and selection.errors == ()


def test_a_moveit_pro_loader_kinema_lacks_is_a_warning_and_an_unknown_name_an_error() -> None:
    catalog, _ = available_plugins()
    selection = select_loaders(
        ["moveit_pro::behaviors::VisionBehaviorsLoader", "kinema::ExampleBehaviorLoader"], catalog
    )
    assert len(selection.warnings) == 1 and "VisionBehaviorsLoader" in selection.warnings[0]
    assert len(selection.errors) == 1
    message = str(selection.errors[0])
    assert "unknown behavior loader 'kinema::ExampleBehaviorLoader'" in message
    assert "did you mean 'kinema::ExampleBehaviorsLoader'" in message


def test_a_workspace_package_overlays_a_bundled_loader_of_the_same_name(
    workspace: Path, make_package
) -> None:
    make_package("my_examples", loader="kinema::ExampleBehaviorsLoader")
    catalog, _ = available_plugins(workspace)
    spec = catalog["kinema::ExampleBehaviorsLoader"]
    assert spec.source is PluginSource.WORKSPACE
    assert spec.root == (workspace / "src" / "my_examples").resolve()
    assert spec.hot_reloadable


def test_a_declared_module_that_does_not_exist_is_reported(tmp_path: Path) -> None:
    (tmp_path / "pyproject.toml").write_text(
        '[project]\nname = "broken"\n'
        '[project.entry-points."kinema.behaviors"]\n"broken::Loader" = "nowhere"\n'
    )
    with pytest.raises(PluginError, match=r"'broken::Loader' = 'nowhere'.*does not exist"):
        read_behavior_package(tmp_path, PluginSource.WORKSPACE)
