from __future__ import annotations

from pathlib import Path

import pytest

from kinema.config.schema import validate_document
from kinema.config.yamlsource import load_yaml_file, parse_yaml
from kinema.errors import ConfigError

COMPAT_CONFIGS = ["lab_sim_config.yaml", "picknik_ur_base_config.yaml", "behavior_hub_catalog_config.yaml"]


@pytest.mark.parametrize("name", COMPAT_CONFIGS)
def test_moveit_pro_config_files_parse_and_validate(shared_dir: Path, name: str):
    document = load_yaml_file(shared_dir / "compat" / "moveit_pro" / "config" / name)
    notices = validate_document(document, name)
    assert isinstance(document.data, dict)
    # keys Kinema does not use are kept and noted, never fatal
    assert all(":" in notice for notice in notices)


def test_every_file_in_the_compat_config_folder_parses(shared_dir: Path):
    folder = shared_dir / "compat" / "moveit_pro" / "config"
    files = sorted(folder.glob("*.yaml"))
    assert files
    for path in files:
        assert load_yaml_file(path).data is not None


def test_unused_and_unknown_keys_are_kept_and_reported_with_their_line():
    document = parse_yaml(
        "hardware:\n  launch_control_node: true\n  robot_descripton: {}\nmy_site_key: 3\n", "config.yaml"
    )
    notices = validate_document(document, "p")
    assert document.data["my_site_key"] == 3
    assert any(n.startswith("config.yaml:4:") and "unknown key 'my_site_key'" in n for n in notices)
    assert any(n.startswith("config.yaml:3:") and "did you mean 'robot_description'" in n for n in notices)
    assert any(n.startswith("config.yaml:2:") and "not used by Kinema" in n for n in notices)


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        ("hardware: [1, 2]\n", 1, "hardware must be a mapping, not a list; valid keys: launch_control_node"),
        ("based_on_package:\n  name: x\n", 1, "based_on_package must be a string"),
        ("hardware:\n  launch_control_node: maybe\n", 2, "must be true or false, not the string 'maybe'"),
        (
            "hardware:\n  robot_description:\n    urdf:\n      pakage: a\n      path: b\n",
            3,
            "must be a reference {package: NAME, path: PATH} or {package_name: NAME, relative_path: PATH} "
            "(unexpected pakage; missing package); valid keys: package, path",
        ),
        (
            "objectives:\n  objective_library_paths:\n    lib: objectives/\n",
            3,
            "objective_library_paths.lib must be a reference",
        ),
        ("objectives:\n  behavior_loader_plugins:\n    core: kinema::Core\n", 3, "core must be a list"),
        ("objectives:\n  behavior_loader_plugins:\n    core: [1]\n", 3, "core[0] must be a string"),
        (
            "moveit_params:\n  trajectory_execution:\n    allowed_start_tolerance: yes\n",
            3,
            "must be a number",
        ),
        (
            "hardware:\n  robot_description:\n    urdf_params:\n      - a: 1\n        b: 2\n",
            4,
            "one-key mapping",
        ),
        (
            "objectives:\n  waypoints_file:\n    package_name: p\n    relative_path: 7\n",
            4,
            "must be a non-empty string",
        ),
    ],
)
def test_wrong_types_name_file_line_key_and_valid_keys(text: str, line: int, words: str):
    document = parse_yaml(text, "config.yaml")
    with pytest.raises(ConfigError) as caught:
        validate_document(document, "p")
    assert str(caught.value).startswith(f"config.yaml:{line}:"), str(caught.value)
    assert words in str(caught.value)


def test_empty_lists_written_as_nothing_are_accepted():
    document = parse_yaml("ros2_control:\n  controllers_not_managed:\n", "config.yaml")
    validate_document(document, "p")
