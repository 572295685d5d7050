"""MoveIt Pro's lab_sim objective library, validated as a user's config would load it.

The 83 public lab_sim objectives (and picknik_ur_base_config's, which their SubTrees reach) are copied
into a config package based on Kinema's lab_sim, then every objective is validated with its SubTree
closure against the config's behaviors. Issue 12 requires 27 of them, issue 14's point-cloud half 13
more, its AprilTag half 5 more and its force objectives 3 more, issue 30's segmentation behaviors 9 more
(which fail when run: Kinema runs no segmentation model), its MPC behaviors 5 more and its core subtrees and
UI behaviors 3 more; ``kinema objective list`` must say in one line why each of the others cannot load.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
import yaml
from click.testing import CliRunner

CONFIG = "moveit_lab_sim"
SHARED_DIR = Path(__file__).resolve().parents[3].parent / "shared"

# The 7 that validated before issue 12, and the 20 it adds.
BEFORE = {
    "3_waypoint_pick_and_place",
    "close_gripper",
    "cycle_between_waypoints",
    "joint_diagnostic",
    "look_at_table",
    "open_gripper",
    "reset_mujoco_robot",
}
ADDED = {
    "add_table_to_planning_scene",
    "addcollisionboxinfrontofendeffector",
    "addcollisionobjecttoplanningscene",
    "clear_previous_obstacles",
    "computelinkposefromwaypoint",
    "create_pcl_poses_vector",
    "create_pose_vector",
    "errorcheckvectorsize",
    "fan_pose_about_tool_z_subtree",
    "get_pose_at_gripper_and_display",
    "get_transform_frame_pose",
    "load_and_execute_joint_trajectory",
    "load_mujoco_robot_state",
    "plan_and_save_trajectory",
    "playback_square_trajectory",
    "record_and_replay_scanning_motion",
    "reflect_poses_subtree",
    "save_robot_joint_state",
    "vector_and_string_example",
    "visualize_grasp_link",
}
# Issue 14's point-cloud objectives (the perception family of the core behaviors).
POINT_CLOUDS = {
    "add_point_cloud_to_vector",
    "fit_bottle_model_subtree",
    "fuse_multiple_views_subtree",
    "grasp_planning",
    "load_and_visualize_point_cloud",
    "octomap_example",
    "register_cad_part",
    "register_cad_part_subtree",
    "scan_scene_-_multiple_point_clouds",
    "stitch_multiple_point_clouds_together",
    "take_picture_with_wrist_camera",
    "take_snap",
    "wrist_snap",
}
# Issue 14's AprilTag half: detection, tag picks, and the camera subtrees they reach.
APRILTAGS = {
    "apriltag_pick_object",
    "get_april_tag_pose_from_image",
    "grasp_pose_using_yaml",
    "pick_april_tag_object_with_approval",
    "pick_up_cube",
    "take_picture_with_wrist_camera",
    "wrist_snap",
}
# Issue 14's force objectives: velocity-force control and the tray-place objective that uses it.
FORCE = {
    "force_relaxation",
    "move_with_velocity_and_force",
    "pick_all_bottles_with_apriltags",
}

# Issue 30's ML objectives: the segmentation behaviors are known (they fail when run, with no model).
ML = {
    "addbottlestoplanningscene",
    "get_bottle_grasp_via_icp_subtree",
    "ml_segment_bottles_from_file",
    "ml_segment_image",
    "ml_segment_image_loop",
    "ml_segment_point_cloud",
    "pick_1_pill_bottle_with_sam3",
    "pick_all_pill_bottles",
    "segment_bottle_subtree",
}
# Issue 30's core subtree "Request Teleoperation" and the UI behaviors (GetPointsFromUser,
# CreateBoundingBoxFromOffset): the objectives that need them validate (the ML ones still fail when they run).
USER_INPUT = {
    "grasp_pose_tuning_with_april_tag",
    "ml_find_bottles_on_table_from_image_exemplar",
    "ml_segment_point_cloud_from_clicked_point",
}
# ... and the parent package's subtrees they reach.
ML_BASE = {
    "segment_image_from_no_negative_text_prompt_subtree",
    "segment_image_from_text_prompt_subtree",
    "segment_point_cloud_from_text_prompt_subtree",
    "segment_image_from_point_subtree",
    "segment_point_cloud_from_clicked_point_subtree",
}

# Issue 30's MPC objectives: MPCPoseTracking, MPCSphereClearance and MPCPointCloudClearance.
MPC = {
    "mpc_pose_tracking",
    "mpc_pose_tracking_dynamic_point_cloud_avoidance_with_sphere_down_sample",
    "mpc_pose_tracking_static_point_cloud_avoidance_with_sphere_down_sample",
    "mpc_pose_tracking_with_point_cloud_avoidance",
    "mpc_pose_tracking_with_static_sphere_point_cloud_avoidance",
}

BROKEN = """<?xml version="1.0" encoding="UTF-8" ?>
<root BTCPP_format="4" main_tree_to_execute="Unknown Behavior Example">
  <BehaviorTree ID="Unknown Behavior Example">
    <Action ID="NoSuchBehavior" />
  </BehaviorTree>
  <TreeNodesModel>
    <SubTree ID="Unknown Behavior Example">
      <MetadataFields><Metadata runnable="true" /></MetadataFields>
    </SubTree>
  </TreeNodesModel>
</root>
"""


@pytest.fixture(scope="module")
def corpus_workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A workspace whose config ``moveit_lab_sim`` (based on lab_sim) holds copies of the corpus libraries."""
    corpus = SHARED_DIR / "compat" / "moveit_pro"
    if not (corpus / "lab_sim" / "objectives").is_dir():
        pytest.skip(f"{corpus}/lab_sim/objectives (MoveIt Pro's lab_sim library) is not beside this checkout")
    root = tmp_path_factory.mktemp("ws")
    package = root / "src" / CONFIG
    (package / "config").mkdir(parents=True)
    shutil.copytree(corpus / "lab_sim" / "objectives", package / "objectives")
    shutil.copytree(corpus / "picknik_ur_base_config" / "objectives", package / "base_objectives")
    # One objective that cannot load whatever Kinema grows to: the listing's example of a reason.
    (package / "broken_objectives").mkdir()
    (package / "broken_objectives" / "unknown_behavior.xml").write_text(BROKEN)
    (package / "package.xml").write_text(
        f'<?xml version="1.0"?>\n<package format="3"><name>{CONFIG}</name><version>0.0.0</version>'
        "<description>MoveIt Pro's lab_sim objectives</description>"
        "<maintainer email='t@example.com'>t</maintainer><license>BSD-3-Clause</license></package>\n"
    )
    config = {
        "based_on_package": "lab_sim",
        "objectives": {
            "objective_library_paths": {
                # Replaces Kinema's own lab_sim library (same key); Kinema's core library stays.
                "lab_sim_objectives": {"package_name": CONFIG, "relative_path": "objectives"},
                "base_objectives": {"package_name": CONFIG, "relative_path": "base_objectives"},
                "broken_objectives": {"package_name": CONFIG, "relative_path": "broken_objectives"},
            }
        },
    }
    (package / "config" / "config.yaml").write_text(yaml.safe_dump(config, sort_keys=False))
    return root


def test_the_required_lab_sim_objectives_validate_with_their_subtrees(corpus_workspace: Path) -> None:
    from kinema.config import ObjectiveLibrary, Workspace, resolve_config
    from kinema.plugins import BehaviorHost
    from kinema.runtime.library_check import file_problem

    resolved = resolve_config(CONFIG, Workspace.discover(corpus_workspace))
    library = ObjectiveLibrary.load(resolved)
    host = BehaviorHost.for_config(resolved)
    host.load().raise_for_errors()
    factory = host.registry.create_factory()

    files = sorted((corpus_workspace / "src" / CONFIG / "objectives").glob("*.xml"))
    assert len(files) == 83, "the corpus should hold the 83 lab_sim objective files"
    problems = {path.stem: file_problem(library, path, factory) for path in files}
    valid = {stem for stem, problem in problems.items() if problem is None}
    failing = {stem: problem for stem, problem in problems.items() if problem is not None}
    required = BEFORE | ADDED | POINT_CLOUDS | APRILTAGS | FORCE | ML | MPC | USER_INPUT
    missing = sorted(required - valid)
    report = "\n".join(f"  {stem}: {failing.get(stem, '?')}" for stem in missing)
    assert not missing, f"{len(valid)} of 83 validate; these required ones do not:\n{report}"
    assert len(valid) >= len(required)
    base = corpus_workspace / "src" / CONFIG / "base_objectives"
    base_problems = {stem: file_problem(library, base / f"{stem}.xml", factory) for stem in sorted(ML_BASE)}
    assert base_problems == dict.fromkeys(ML_BASE), base_problems


def test_objective_list_says_why_each_objective_cannot_load(corpus_workspace: Path) -> None:
    from kinema.cli.main import cli

    result = CliRunner().invoke(cli, ["objective", "list", "-w", str(corpus_workspace), "-c", CONFIG])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    header = next(i for i, line in enumerate(lines) if line.endswith("objectives cannot load:"))
    count = int(lines[header].split()[0])
    reasons = lines[header + 1 : header + 1 + count]
    assert len(reasons) == count > 0, result.output
    # One line each: the objective, then file:line: the first problem.
    broken = next(line for line in reasons if line.strip().startswith("Unknown Behavior Example:"))
    assert "unknown_behavior.xml:" in broken and "Node not recognized: NoSuchBehavior" in broken, broken
    table = {line[4:].split("  ")[0].strip(): line[:3] for line in lines[:header] if line[:1] in "R-"}
    assert table["Unknown Behavior Example"].endswith("!")
    assert not table["MPC Pose Tracking"].endswith("!")
    assert not table["Take Scene Camera Snapshot"].endswith("!")
    assert not table["Vector and String Example"].endswith("!")
    as_json = CliRunner().invoke(
        cli, ["objective", "list", "-w", str(corpus_workspace), "-c", CONFIG, "--json"]
    )
    cannot_load = json.loads(as_json.output)["cannot_load"]
    assert len(cannot_load) == count and "NoSuchBehavior" in cannot_load["Unknown Behavior Example"]


def test_every_port_the_corpus_sets_on_a_kinema_behavior_is_declared(registry: Any) -> None:
    """Beyond the files that validate: wherever MoveIt Pro's files use a behavior Kinema has, the ports
    they set exist (a file failing on another behavior first would hide a missing port)."""
    from lxml import etree

    from kinema.bt.names import RESERVED_ATTRIBUTES

    corpus = SHARED_DIR / "compat" / "moveit_pro"
    files = sorted(corpus.glob("**/*.xml"))
    if not files:
        pytest.skip(f"{corpus} is not beside this checkout")
    undeclared: dict[str, set[str]] = {}
    for path in files:
        for element in etree.parse(str(path)).getroot().iter("Action", "Decorator", "Condition", "Control"):
            behavior_id = element.get("ID")
            if behavior_id not in registry:
                continue
            declared = {port.name for port in registry[behavior_id].ports}
            extra = {
                name
                for name in element.attrib
                if name not in declared and name not in RESERVED_ATTRIBUTES and not name.startswith("_")
            } - {"ID", "name"}
            if extra:
                undeclared.setdefault(behavior_id, set()).update(extra)
    assert not undeclared, f"ports MoveIt Pro's files set that Kinema's behaviors lack: {undeclared}"
