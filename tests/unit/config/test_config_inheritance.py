from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from kinema.config import Workspace, resolve_config
from kinema.config.inheritance import merge_layers
from kinema.errors import ConfigError


def test_merge_rules_table():
    parent = {
        "hardware": {
            "robot_description": {
                "urdf": {"package": "p", "path": "a.urdf"},
                "srdf": {"package": "p", "path": "a.srdf"},
            }
        },
        "moveit_params": {
            "joint_group_name": "manipulator",
            "publish": {"planning_scene": True, "state_updates": True},
        },
        "ros2_control": {"controllers_active_at_startup": ["a", "b", "c"]},
        "objectives": {
            "behavior_loader_plugins": {"core": ["Core", "Vision"], "extra": ["Extra"]},
            "objective_library_paths": {
                "core": {"package_name": "p", "relative_path": "objectives"},
                "sim": {"package_name": "p", "relative_path": "sim"},
            },
            "waypoints_file": {"package_name": "p", "relative_path": "w.yaml"},
        },
    }
    child = {
        "based_on_package": "p",
        "hardware": {"robot_description": {"urdf": {"package_name": "c", "relative_path": "b.urdf"}}},
        "moveit_params": {"publish": {"state_updates": False}},
        "ros2_control": {"controllers_active_at_startup": ["z"]},
        "objectives": {
            "behavior_loader_plugins": {"core": ["Core", "Mujoco"], "nav": ["Nav"]},
            "objective_library_paths": {"sim": {"package_name": "c", "relative_path": "objectives"}},
            "waypoints_file": {"package": "c", "path": "mine.yaml"},
        },
    }
    merged, origins = merge_layers([("p", parent), ("c", child)])
    # maps merge recursively, child wins
    assert merged["moveit_params"] == {
        "joint_group_name": "manipulator",
        "publish": {"planning_scene": True, "state_updates": False},
    }
    # a reference is one value: the child's replaces the parent's wholesale, whatever its shape
    assert merged["hardware"]["robot_description"]["urdf"] == {"package_name": "c", "relative_path": "b.urdf"}
    assert merged["hardware"]["robot_description"]["srdf"] == {"package": "p", "path": "a.srdf"}
    # lists are replaced
    assert merged["ros2_control"]["controllers_active_at_startup"] == ["z"]
    # behavior loaders are the union across the chain
    assert merged["objectives"]["behavior_loader_plugins"] == {
        "core": ["Core", "Vision", "Mujoco"],
        "extra": ["Extra"],
        "nav": ["Nav"],
    }
    # objective libraries merge by key; reusing a key replaces that entry
    assert merged["objectives"]["objective_library_paths"] == {
        "core": {"package_name": "p", "relative_path": "objectives"},
        "sim": {"package_name": "c", "relative_path": "objectives"},
    }
    assert merged["objectives"]["waypoints_file"] == {"package": "c", "path": "mine.yaml"}
    # provenance of every leaf
    assert origins[("moveit_params", "joint_group_name")] == "p"
    assert origins[("moveit_params", "publish", "state_updates")] == "c"
    assert origins[("moveit_params", "publish", "planning_scene")] == "p"
    assert origins[("hardware", "robot_description", "urdf")] == "c"
    assert ("hardware", "robot_description", "urdf", "package") not in origins
    assert origins[("objectives", "behavior_loader_plugins", "core", 0)] == "p"
    assert origins[("objectives", "behavior_loader_plugins", "core", 2)] == "c"
    assert origins[("objectives", "objective_library_paths", "core")] == "p"
    assert origins[("objectives", "objective_library_paths", "sim")] == "c"
    assert origins[("ros2_control", "controllers_active_at_startup")] == "c"
    # the inputs are not changed by merging
    assert parent["objectives"]["behavior_loader_plugins"]["core"] == ["Core", "Vision"]


def test_a_child_replacing_a_map_with_a_scalar_drops_the_old_provenance():
    merged, origins = merge_layers([("p", {"a": {"b": 1, "c": 2}}), ("c", {"a": 5})])
    assert merged == {"a": 5}
    assert origins == {("a",): "c"}


def test_five_level_chain_resolves_root_first_with_provenance(ws):
    ws.config("level0")
    for level in range(1, 5):
        ws.child(
            f"level{level}", f"level{level - 1}", {"moveit_params": {"joint_group_name": f"group{level}"}}
        )
    resolved = resolve_config("level4", Workspace.discover(ws.root))
    assert resolved.chain == ["level0", "level1", "level2", "level3", "level4"]
    assert resolved.get("moveit_params.joint_group_name") == "group4"
    assert resolved.provenance["moveit_params.joint_group_name"] == "level4"
    assert resolved.provenance["hardware.robot_description.urdf"] == "level0"
    assert resolved.provenance["objectives.objective_library_paths.level2_objectives"] == "level2"
    assert [lib.key for lib in resolved.objective_library_paths] == [f"level{i}_objectives" for i in range(5)]
    assert resolved.urdf_path == ws.root / "src" / "level0" / "description" / "robot.urdf"
    assert resolved.waypoints_path == ws.root / "src" / "level0" / "waypoints" / "waypoints.yaml"
    location = resolved.location_of("moveit_params.joint_group_name")
    assert location.file.endswith("level4/config/config.yaml")
    assert location.line > 0


def test_a_cycle_is_an_error_that_prints_it(ws):
    ws.child("a", "c")
    ws.child("b", "a")
    ws.child("c", "b")
    with pytest.raises(ConfigError) as caught:
        resolve_config("a", Workspace.discover(ws.root))
    assert "inheritance cycle: a → c → b → a" in str(caught.value)
    assert "config.yaml:1:" in str(caught.value)


def test_a_config_based_on_itself_is_a_cycle(ws):
    ws.child("selfish", "selfish")
    with pytest.raises(ConfigError, match="inheritance cycle: selfish → selfish"):
        resolve_config("selfish", Workspace.discover(ws.root))


def test_a_missing_parent_lists_the_known_packages(ws):
    ws.config("robot_base")
    ws.child("robot_site", "robot_bas")
    with pytest.raises(ConfigError) as caught:
        resolve_config("robot_site", Workspace.discover(ws.root))
    message = str(caught.value)
    assert "based on 'robot_bas', which is not a known package" in message
    assert "did you mean 'robot_base'" in message
    assert "lab_sim" in message
    assert "robot_site/config/config.yaml:1:" in message


def test_unknown_config_lists_the_config_packages(ws):
    ws.config("robot_a")
    with pytest.raises(ConfigError, match=r"no config package named 'robot_x'.*robot_a"):
        resolve_config("robot_x", Workspace.discover(ws.root))


def test_a_parent_that_is_not_a_config_package_is_an_error(ws):
    ws.child("robot", "kinema_objectives")
    with pytest.raises(ConfigError, match=r"'kinema_objectives' .* is not a config package"):
        resolve_config("robot", Workspace.discover(ws.root))


def test_a_missing_referenced_file_is_an_error_at_the_line_that_set_it(ws):
    ws.config("base")
    ws.child(
        "site",
        "base",
        {"hardware": {"robot_description": {"srdf": {"package": "site", "path": "nope.srdf"}}}},
    )
    with pytest.raises(ConfigError) as caught:
        resolve_config("site", Workspace.discover(ws.root))
    message = str(caught.value)
    assert "site/config/config.yaml:" in message
    assert "hardware.robot_description.srdf: site/nope.srdf does not exist" in message


def test_a_reference_to_an_unknown_package_names_it(ws):
    data = ws.root_data("base")
    data["objectives"]["objective_library_paths"]["extra"] = {
        "package_name": "ghost_pkg",
        "relative_path": "x",
    }
    ws.config("base", data)
    with pytest.raises(ConfigError, match="refers to package 'ghost_pkg', which is not in workspace"):
        resolve_config("base", Workspace.discover(ws.root))


def test_a_folder_where_a_file_is_expected_is_an_error(ws):
    data = ws.root_data("base")
    data["hardware"]["robot_description"]["urdf"] = {"package": "base", "path": "description"}
    ws.config("base", data)
    with pytest.raises(ConfigError, match="is a folder, a file is expected"):
        resolve_config("base", Workspace.discover(ws.root))


def test_missing_required_key_is_an_error_with_a_typo_hint(ws):
    data = ws.root_data("base")
    data["objectivs"] = data.pop("objectives")
    ws.config("base", data)
    with pytest.raises(ConfigError) as caught:
        resolve_config("base", Workspace.discover(ws.root))
    assert "does not set objectives.behavior_loader_plugins, which is required" in str(caught.value)
    assert "did you mean 'objectives'" in str(caught.value)


def test_check_files_false_resolves_without_the_files(ws):
    data = ws.root_data("base")
    data["hardware"]["robot_description"]["urdf"] = {"package": "base", "path": "later.urdf"}
    ws.config("base", data)
    resolved = resolve_config("base", Workspace.discover(ws.root), check_files=False)
    with pytest.raises(ConfigError, match=r"later.urdf does not exist"):
        _ = resolved.urdf_path


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("hardware: [\n", "invalid YAML"),
        ("- just\n- a list\n", "config.yaml must be a mapping"),
        ("based_on_package: 5\n", "based_on_package must be a string"),
    ],
)
def test_broken_config_files_are_clear_errors(ws, text: str, words: str):
    ws.config("broken", text)
    with pytest.raises(ConfigError, match=words):
        resolve_config("broken", Workspace.discover(ws.root))


def test_non_utf8_and_huge_config_files_are_clear_errors(ws):
    package = ws.config("latin")
    (package / "config" / "config.yaml").write_bytes(b"based_on_package: caf\xe9\n")
    with pytest.raises(ConfigError, match="not UTF-8"):
        resolve_config("latin", Workspace.discover(ws.root))
    package = ws.config("huge")
    (package / "config" / "config.yaml").write_text("# " + "x" * (3 * 1024 * 1024) + "\n")
    with pytest.raises(ConfigError, match="larger than the limit"):
        resolve_config("huge", Workspace.discover(ws.root))


def test_moveit_pro_chain_from_the_compat_files(shared_dir: Path, ws):
    compat = shared_dir / "compat" / "moveit_pro" / "config"
    for name, file in [
        ("picknik_ur_base_config", "picknik_ur_base_config.yaml"),
        ("lab_sim", "lab_sim_config.yaml"),
        ("behavior_hub_catalog", "behavior_hub_catalog_config.yaml"),
    ]:
        package = ws.config(name)
        shutil.copy(compat / file, package / "config" / "config.yaml")
    resolved = resolve_config("behavior_hub_catalog", Workspace.discover(ws.root), check_files=False)
    assert resolved.chain == ["picknik_ur_base_config", "lab_sim", "behavior_hub_catalog"]
    loaders = resolved.behavior_loader_plugins
    assert loaders["nav"] == ["moveit_pro::behaviors::NavBehaviorsLoader"]
    assert loaders["lab_sim"] == ["lab_sim_behaviors::LabSimBehaviorsLoader"]
    assert "moveit_pro::behaviors::MujocoBehaviorsLoader" in loaders["core"]
    assert "moveit_pro::behaviors::VisionBehaviorsLoader" in loaders["core"]
    libraries = resolved.get("objectives.objective_library_paths")
    assert list(libraries) == [
        "core_objectives",
        "motion_objectives",
        "perception_objectives",
        "visualization_objectives",
        "simulation_objectives",
        "mujoco_objectives",
        "sim_objectives",
    ]
    # lab_sim overrides four moveit_params refs and inherits the rest
    assert resolved.provenance["moveit_params.joint_limits"] == "lab_sim"
    assert resolved.provenance["moveit_params.kinematics"] == "picknik_ur_base_config"
    assert (
        resolved.provenance["moveit_params.trajectory_execution.allowed_start_tolerance"]
        == "picknik_ur_base_config"
    )
    assert resolved.get("objectives.waypoints_file") == {
        "package_name": "lab_sim",
        "relative_path": "waypoints/ur_waypoints.yaml",
    }
    # lab_sim's urdf_params list replaces the parent's
    assert resolved.get("hardware.robot_description.urdf_params")[0] == {"mujoco_keyframe": "default"}
    # the moveit_pro_objectives libraries resolve to Kinema's core library
    assert resolved.resolve_file("objectives.objective_library_paths.mujoco_objectives").name == "objectives"


def test_bundled_lab_sim_and_example_config_resolve():
    workspace = Workspace.bundled_only()
    resolved = resolve_config("example_config", workspace)
    assert resolved.chain == ["lab_sim", "example_config"]
    assert resolved.urdf_path.name == "lab_sim.urdf"
    assert resolved.srdf_path.name == "lab_sim.srdf"
    assert resolved.mujoco_model_path is not None and resolved.mujoco_model_path.name == "lab_sim_scene.xml"
    assert resolved.joint_limits_path is not None and resolved.joint_limits_path.name == "joint_limits.yaml"
    assert resolved.waypoints_path is not None and resolved.waypoints_path.name == "lab_sim_waypoints.yaml"
    loaders = resolved.behavior_loader_plugins
    assert loaders["core"] == ["kinema::CoreBehaviorsLoader", "kinema::MujocoBehaviorsLoader"]  # from lab_sim
    assert resolved.provenance["objectives.behavior_loader_plugins.core[0]"] == "lab_sim"
    assert resolved.get("ros2_control.controllers_active_at_startup") == [
        "joint_state_broadcaster",
        "force_torque_sensor_broadcaster",
        "joint_trajectory_controller",
        "robotiq_gripper_controller",
    ]
    assert [lib.package for lib in resolved.objective_library_paths] == [
        "kinema_objectives",
        "lab_sim",
        "example_config",
    ]
