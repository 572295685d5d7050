"""The files family: MoveIt Pro's YAML layouts, path resolution in the objectives folder, atomic saves."""

from __future__ import annotations

import shutil
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import tick_behavior

CORPUS = (
    Path(__file__).resolve().parents[3].parent / "shared" / "compat" / "moveit_pro" / "lab_sim" / "objectives"
)


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An objectives folder: offline contexts (no config) resolve relative paths in the working directory."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.fixture
def offline(node: Any) -> BehaviorContext:
    return BehaviorContext(node)


def _corpus_file(name: str, folder: Path) -> Path:
    source = CORPUS / name
    if not source.is_file():
        pytest.skip(f"{source} (MoveIt Pro's lab_sim files) is not beside this checkout")
    return Path(shutil.copy(source, folder / name))


def test_moveit_pros_yaml_files_load(behavior: Any, offline: BehaviorContext, folder: Path) -> None:
    _corpus_file("joint_trajectory.yaml", folder)
    _corpus_file("robot_joint_state.yaml", folder)
    _corpus_file("pill_bottle_place_poses.yaml", folder)
    _corpus_file("relative_grasp_pose.yaml", folder)
    run = tick_behavior(
        behavior("LoadJointTrajectoryFromYaml"), {"file_path": "joint_trajectory.yaml"}, context=offline
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    trajectory = run.outputs["output"]
    assert trajectory.joint_names[0] == "linear_rail_joint" and len(trajectory.points) > 10
    state = tick_behavior(
        behavior("LoadRobotJointStateFromYaml"), {"file_path": "robot_joint_state.yaml"}, context=offline
    ).outputs["output"]
    assert state.joint_state.position[2] == pytest.approx(-1.8849, abs=1e-4)
    poses = tick_behavior(
        behavior("LoadPoseStampedVectorFromYaml"),
        {"file_path": "pill_bottle_place_poses.yaml"},
        context=offline,
    ).outputs["output"]
    assert len(poses) > 1 and poses[0].pose.position.x == pytest.approx(0.9806297649587842)
    pose = tick_behavior(
        behavior("LoadPoseStampedFromYaml"), {"file_path": "relative_grasp_pose.yaml"}, context=offline
    ).outputs["output"]
    assert pose.header.frame_id == "world"


def test_saved_files_load_back_and_keep_an_old_file_unless_told(
    behavior: Any, offline: BehaviorContext, folder: Path
) -> None:
    pose = tick_behavior(
        behavior("CreatePoseStamped"), {"position_xyz": [0.1, 0.2, 0.3]}, context=offline
    ).outputs["pose_stamped"]
    save = behavior("SavePoseStampedToYaml")
    assert (
        tick_behavior(save, {"message": pose, "yaml_filename": "grasp"}, context=offline).status
        == NodeStatus.SUCCESS
    )
    assert (folder / "grasp.yaml").is_file()
    loaded = tick_behavior(behavior("LoadPoseStampedFromYaml"), {"file_path": "grasp.yaml"}, context=offline)
    assert loaded.outputs["output"].pose.position.z == pytest.approx(0.3)
    before = (folder / "grasp.yaml").read_text()
    moved = tick_behavior(
        behavior("CreatePoseStamped"), {"position_xyz": [9.0, 9.0, 9.0]}, context=offline
    ).outputs["pose_stamped"]
    kept = tick_behavior(
        save, {"message": moved, "yaml_filename": "grasp", "overwrite": False}, context=offline
    )
    assert kept.status == NodeStatus.SUCCESS
    assert (folder / "grasp.yaml").read_text() == before
    assert len(list(folder.glob("grasp_*.yaml"))) == 1
    replaced = tick_behavior(
        save, {"message": moved, "yaml_filename": "grasp", "overwrite": True}, context=offline
    )
    assert replaced.status == NodeStatus.SUCCESS and "9.0" in (folder / "grasp.yaml").read_text()
    assert not list(folder.glob("*.tmp*")) and not list(folder.glob(".*"))


def test_a_save_never_leaves_its_folder(behavior: Any, offline: BehaviorContext, folder: Path) -> None:
    pose = tick_behavior(behavior("CreatePoseStamped"), {}, context=offline).outputs["pose_stamped"]
    run = tick_behavior(
        behavior("SavePoseStampedToYaml"), {"message": pose, "yaml_filename": "../escaped"}, context=offline
    )
    assert run.status == NodeStatus.FAILURE
    assert "port [yaml_filename]" in run.toasts[-1] and "leaves the folder" in run.toasts[-1]
    assert not (folder.parent / "escaped.yaml").exists()


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        (None, "no such file"),
        ("header: [unclosed", "is not valid YAML"),
        ("header: {frame_id: world}\nposition: {x: 1}\n", "is not a geometry_msgs/msg/PoseStamped"),
        ("- 1\n- 2\n", "holds list"),
    ],
)
def test_missing_and_malformed_yaml_fail_naming_the_file(
    behavior: Any, offline: BehaviorContext, folder: Path, content: str | None, expected: str
) -> None:
    if content is not None:
        (folder / "pose.yaml").write_text(content)
    run = tick_behavior(behavior("LoadPoseStampedFromYaml"), {"file_path": "pose.yaml"}, context=offline)
    assert run.status == NodeStatus.FAILURE
    assert "port [file_path]" in run.toasts[-1] and expected in run.toasts[-1], run.toasts[-1]


def test_text_and_image_files(behavior: Any, offline: BehaviorContext, folder: Path) -> None:
    (folder / "note.txt").write_text("hello\nworld\n")
    text = tick_behavior(behavior("ReadTextFileAsString"), {"text_filename": "note.txt"}, context=offline)
    assert text.outputs["string_file_contents"] == "hello\nworld\n"
    from kinema.transport import from_dict

    pixels = np.zeros((4, 6, 3), dtype=np.uint8)
    pixels[1, 2] = [255, 10, 20]
    image = from_dict(
        "sensor_msgs/msg/Image",
        {"height": 4, "width": 6, "encoding": "rgb8", "step": 18, "data": pixels.reshape(-1)},
    )
    saved = tick_behavior(behavior("SaveImageToFile"), {"image": image, "file_path": "shot"}, context=offline)
    assert saved.status == NodeStatus.SUCCESS, saved.toasts
    loaded = tick_behavior(behavior("LoadImageFromFile"), {"file_path": "shot.png"}, context=offline)
    back = loaded.outputs["image"]
    assert (back.width, back.height, back.encoding) == (6, 4, "rgb8")
    assert np.array_equal(np.asarray(back.data).reshape(4, 6, 3), pixels)


def test_a_git_lfs_pointer_is_named_as_one_not_as_a_bad_image_or_a_mesh(
    behavior: Any, offline: BehaviorContext, folder: Path
) -> None:
    """MoveIt Pro's example images and meshes are Git LFS pointers in a clone without `git lfs pull`: the
    image failed as 'not an image Pillow reads', the mesh was drawn as nothing without a word."""
    pointer = (
        "version https://git-lfs.github.com/spec/v1\n"
        "oid sha256:4d7a214614ab2935c943f9e0ff69d22eadbb8f32b1258daaa5e2ca24d17e2393\nsize 12345\n"
    )
    (folder / "real_lab1.png").write_text(pointer)
    (folder / "gripper_token.dae").write_text(pointer)
    image = tick_behavior(behavior("LoadImageFromFile"), {"file_path": "real_lab1.png"}, context=offline)
    from kinema.transport import from_dict

    pose = from_dict("geometry_msgs/msg/PoseStamped", {"header": {"frame_id": "world"}})
    mesh = tick_behavior(
        behavior("VisualizeMesh"), {"mesh_path": "gripper_token.dae", "mesh_pose": pose}, context=offline
    )
    assert image.status == NodeStatus.FAILURE
    assert "is a Git LFS pointer file, not the file itself; run `git lfs pull`" in image.toasts[-1]
    # Only a picture: the objective goes on, saying why nothing shows (MoveIt Pro's Visualize Grasp Link).
    assert mesh.status == NodeStatus.SUCCESS
    assert "is a Git LFS pointer file, not the mesh: nothing drawn" in mesh.toasts[-1]


def _my_cell(tmp_path: Path) -> tuple[Path, Any]:
    """A workspace package ``my_cell`` based on lab_sim with an objectives folder of its own: its folder
    and its resolved config."""
    import yaml

    from kinema.config import Workspace, resolve_config

    package = tmp_path / "ws" / "src" / "my_cell"
    (package / "config").mkdir(parents=True)
    (package / "objectives").mkdir()
    (package / "package.xml").write_text(
        '<?xml version="1.0"?><package format="3"><name>my_cell</name><version>0.0.0</version>'
        "<description>t</description><maintainer email='t@example.com'>t</maintainer>"
        "<license>BSD-3-Clause</license></package>"
    )
    config = {
        "based_on_package": "lab_sim",
        "objectives": {
            "objective_library_paths": {
                "my_objectives": {"package_name": "my_cell", "relative_path": "objectives"}
            }
        },
    }
    (package / "config" / "config.yaml").write_text(yaml.safe_dump(config))
    return package, resolve_config("my_cell", Workspace.discover(tmp_path / "ws"))


def test_paths_resolve_in_the_configs_objective_folders(behavior: Any, node: Any, tmp_path: Path) -> None:
    """Saves go to the config's own objectives; reads also find inherited ones; MoveIt Pro's
    ``~/user_ws/src/lab_sim/objectives/...`` names the config's own objectives, not the installed lab_sim."""

    package, resolved = _my_cell(tmp_path)
    context = BehaviorContext(node, config=resolved)
    installed = {p.name for p in resolved.package_dir("lab_sim").joinpath("objectives").iterdir()}

    from kinema.transport import from_dict

    trajectory = from_dict(
        "trajectory_msgs/msg/JointTrajectory",
        {"joint_names": ["elbow_joint"], "points": [{"positions": [0.5], "time_from_start": {"sec": 1}}]},
    )
    saved = tick_behavior(
        behavior("SaveJointTrajectoryToYaml"),
        {"message": trajectory, "yaml_filename": "~/user_ws/src/lab_sim/objectives/joint_trajectory"},
        context=context,
    )
    assert saved.status == NodeStatus.SUCCESS, saved.toasts
    assert (package / "objectives" / "joint_trajectory.yaml").is_file()
    assert {p.name for p in resolved.package_dir("lab_sim").joinpath("objectives").iterdir()} == installed
    loaded = tick_behavior(
        behavior("LoadJointTrajectoryFromYaml"), {"file_path": "joint_trajectory.yaml"}, context=context
    )
    assert loaded.outputs["output"].points[0].positions[0] == 0.5
    inherited = tick_behavior(
        behavior("ReadTextFileAsString"), {"text_filename": "close_gripper.xml"}, context=context
    )
    assert (
        inherited.status == NodeStatus.SUCCESS
        and "Close Gripper" in inherited.outputs["string_file_contents"]
    )


def test_package_paths_into_the_chains_objectives_find_the_configs_copy(
    behavior: Any, node: Any, tmp_path: Path
) -> None:
    """``package://lab_sim/objectives/x`` and ``package_name=lab_sim, objectives/x`` in a config based on
    lab_sim name the x beside the config's objectives (where a copy of MoveIt Pro's lab_sim files has it)."""
    import yaml

    from kinema.config import Workspace, resolve_config

    package = tmp_path / "ws" / "src" / "my_cell"
    (package / "config").mkdir(parents=True)
    (package / "objectives").mkdir()
    (package / "package.xml").write_text(
        '<?xml version="1.0"?><package format="3"><name>my_cell</name><version>0.0.0</version>'
        "<description>t</description><maintainer email='t@example.com'>t</maintainer>"
        "<license>BSD-3-Clause</license></package>"
    )
    libraries = {"lab_sim_objectives": {"package_name": "my_cell", "relative_path": "objectives"}}
    config = {"based_on_package": "lab_sim", "objectives": {"objective_library_paths": libraries}}
    (package / "config" / "config.yaml").write_text(yaml.safe_dump(config))
    (package / "objectives" / "token.stl").write_text("solid t\nendsolid t\n")
    from PIL import Image

    Image.new("RGB", (3, 2), (10, 20, 30)).save(package / "objectives" / "lab.png")
    resolved = resolve_config("my_cell", Workspace.discover(tmp_path / "ws"))
    context = BehaviorContext(node, config=resolved)
    image = tick_behavior(
        behavior("LoadImageFromFile"),
        {"file_path": "objectives/lab.png", "package_name": "lab_sim"},
        context=context,
    )
    assert image.status == NodeStatus.SUCCESS, image.toasts
    assert (image.outputs["image"].width, image.outputs["image"].height) == (3, 2)
    received: list[Any] = []
    node.create_subscription(
        "visualization_msgs/msg/MarkerArray",
        "/visualization_marker_array",
        lambda m: received.extend(m.markers),
    )
    pose = tick_behavior(behavior("CreatePoseStamped"), {}, context=context).outputs["pose_stamped"]
    mesh = tick_behavior(
        behavior("VisualizeMesh"),
        {"mesh_path": "package://lab_sim/objectives/token.stl", "mesh_pose": pose},
        context=context,
    )
    assert mesh.status == NodeStatus.SUCCESS, mesh.toasts
    deadline = time.monotonic() + 10
    while not received and time.monotonic() < deadline:
        time.sleep(0.01)
    assert received and received[0].mesh_resource == (package / "objectives" / "token.stl").resolve().as_uri()


@pytest.fixture
def outside(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder that is neither the working directory, a package, nor Kinema's data folder."""
    return tmp_path_factory.mktemp("outside")


@pytest.mark.parametrize("name", ["/etc/passwd", "{outside}/secret.txt", "link/secret.txt", "link_file.txt"])
def test_reads_outside_the_allowed_folders_are_refused_naming_the_rule(
    behavior: Any, offline: BehaviorContext, folder: Path, outside: Path, name: str
) -> None:
    (outside / "secret.txt").write_text("top secret\n")
    (folder / "link").symlink_to(outside, target_is_directory=True)
    (folder / "link_file.txt").symlink_to(outside / "secret.txt")
    path = name.format(outside=outside)
    run = tick_behavior(behavior("ReadTextFileAsString"), {"text_filename": path}, context=offline)
    assert run.status == NodeStatus.FAILURE
    assert "string_file_contents" not in run.outputs
    # A relative path that climbs out through a symlink already leaves its objectives folder.
    rule = "leaves the folder" if name.startswith("link") else "refused by the file rule"
    assert "port [text_filename]" in run.toasts[-1] and rule in run.toasts[-1], run.toasts[-1]


def test_writes_outside_the_allowed_folders_are_refused(
    behavior: Any, offline: BehaviorContext, folder: Path, outside: Path
) -> None:
    pose = tick_behavior(behavior("CreatePoseStamped"), {}, context=offline).outputs["pose_stamped"]
    (folder / "link").symlink_to(outside, target_is_directory=True)
    for name in (str(outside / "written"), "link/written"):
        run = tick_behavior(
            behavior("SavePoseStampedToYaml"), {"message": pose, "yaml_filename": name}, context=offline
        )
        assert run.status == NodeStatus.FAILURE
        assert "refused by the file rule" in run.toasts[-1] or "leaves the folder" in run.toasts[-1]
    assert list(outside.iterdir()) == []


def test_a_file_directly_in_the_temporary_folder_may_be_written_not_read(
    behavior: Any, offline: BehaviorContext
) -> None:
    """MoveIt Pro's objectives save scratch images as /tmp/NAME: allowed; a folder below it, or reading
    anything there back, is not."""
    import tempfile
    import uuid

    pose = tick_behavior(behavior("CreatePoseStamped"), {}, context=offline).outputs["pose_stamped"]
    name = Path(tempfile.gettempdir()) / f"kinema-test-{uuid.uuid4().hex}"
    try:
        written = tick_behavior(
            behavior("SavePoseStampedToYaml"), {"message": pose, "yaml_filename": str(name)}, context=offline
        )
        assert written.status == NodeStatus.SUCCESS, written.toasts
        assert name.with_suffix(".yaml").is_file()
        read = tick_behavior(
            behavior("ReadTextFileAsString"),
            {"text_filename": str(name.with_suffix(".yaml"))},
            context=offline,
        )
        assert read.status == NodeStatus.FAILURE and "refused by the file rule" in read.toasts[-1]
    finally:
        name.with_suffix(".yaml").unlink(missing_ok=True)


def test_the_security_folder_is_never_read_or_written_even_inside_the_workspace(
    behavior: Any, offline: BehaviorContext, folder: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    security = folder / "security"
    security.mkdir()
    (security / "ca.key").write_text("-----BEGIN PRIVATE KEY-----\n")
    monkeypatch.setenv("KINEMA_SECURITY_DIR", str(security))
    read = tick_behavior(
        behavior("ReadTextFileAsString"), {"text_filename": "security/ca.key"}, context=offline
    )
    assert read.status == NodeStatus.FAILURE and "refused by the security rule" in read.toasts[-1]
    pose = tick_behavior(behavior("CreatePoseStamped"), {}, context=offline).outputs["pose_stamped"]
    write = tick_behavior(
        behavior("SavePoseStampedToYaml"),
        {"message": pose, "yaml_filename": "security/pose"},
        context=offline,
    )
    assert write.status == NodeStatus.FAILURE and "refused by the security rule" in write.toasts[-1]
    assert sorted(p.name for p in security.iterdir()) == ["ca.key"]


def test_a_config_allows_its_packages_and_the_data_folder(behavior: Any, node: Any) -> None:
    import platformdirs

    from kinema.config import resolve_config

    context = BehaviorContext(node, config=resolve_config("lab_sim"))
    data = platformdirs.user_data_path("kinema")
    data.mkdir(parents=True, exist_ok=True)
    (data / "note.txt").write_text("kept\n")
    kept = tick_behavior(
        behavior("ReadTextFileAsString"), {"text_filename": str(data / "note.txt")}, context=context
    )
    assert kept.outputs["string_file_contents"] == "kept\n"
    inherited = tick_behavior(
        behavior("ReadTextFileAsString"), {"text_filename": "close_gripper.xml"}, context=context
    )
    assert inherited.status == NodeStatus.SUCCESS, inherited.toasts
    refused = tick_behavior(
        behavior("ReadTextFileAsString"), {"text_filename": "/etc/passwd"}, context=context
    )
    assert refused.status == NodeStatus.FAILURE and "refused by the file rule" in refused.toasts[-1]


def test_a_bundled_config_saves_into_the_user_data_folder_not_into_kinema(behavior: Any, node: Any) -> None:
    """A MoveIt Pro objective run on the bundled lab_sim saved tool_pose.yaml into Kinema's own source tree
    (a checkout, or site-packages): saves for a bundled config go to the user data folder, which reads look
    in first."""
    import platformdirs

    from kinema.config import resolve_config
    from kinema.transport import from_dict

    resolved = resolve_config("lab_sim")
    context = BehaviorContext(node, config=resolved)
    bundled = resolved.package_dir("lab_sim") / "objectives"
    before = sorted(p.name for p in bundled.iterdir())
    pose = from_dict(
        "geometry_msgs/msg/PoseStamped", {"header": {"frame_id": "world"}, "pose": {"position": {"x": 0.25}}}
    )
    saved = tick_behavior(
        behavior("SavePoseStampedToYaml"),
        {"message": pose, "yaml_filename": "~/user_ws/src/lab_sim/objectives/tool_pose", "overwrite": True},
        context=context,
    )
    assert saved.status == NodeStatus.SUCCESS, saved.toasts
    assert sorted(p.name for p in bundled.iterdir()) == before
    assert (platformdirs.user_data_path("kinema") / "files" / "lab_sim" / "tool_pose.yaml").is_file()
    loaded = tick_behavior(
        behavior("LoadPoseStampedFromYaml"), {"file_path": "tool_pose.yaml"}, context=context
    )
    assert loaded.status == NodeStatus.SUCCESS, loaded.toasts
    assert loaded.outputs["output"].pose.position.x == 0.25


def test_a_parameter_override_is_held_to_the_file_rule_like_any_port(
    registry: Any, node: Any, caplog: pytest.LogCaptureFixture
) -> None:
    """A library objective run by name (what an operator may do) with its file parameter overridden."""
    from kinema.config import resolve_config
    from kinema.runtime.objective_server import FactoryTreeSource, ObjectiveRequest, ObjectiveServer
    from kinema.runtime.overrides import ParameterOverride

    factory = registry.create_factory(BehaviorContext(node, config=resolve_config("lab_sim")))
    factory.register_behavior_tree_from_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Peek" _description="reads a note">'
        '<ReadTextFileAsString text_filename="{file}" string_file_contents="{contents}"/>'
        "</BehaviorTree></root>"
    )
    with ObjectiveServer(FactoryTreeSource(factory)) as server:
        for path, rule in (("/etc/passwd", "file rule"), ("~/.config/kinema/security/ca.key", "file rule")):
            overrides = (ParameterOverride("file", path),)
            caplog.clear()
            result = server.submit(ObjectiveRequest("Peek", "", overrides, "test")).wait(30)
            assert result is not None and result.failed, result
            assert f"refused by the {rule}" in caplog.text and "root:" not in caplog.text


def test_no_objective_writes_over_the_files_that_define_the_robot(
    behavior: Any, node: Any, tmp_path: Path
) -> None:
    """A client allowed ad-hoc XML replaced lab_sim's joint limits and waypoints with a pose (a save to an
    absolute path inside a config package): the robot rule refuses it, in the config's package and in an
    inherited bundled one, and the files stay as they were."""

    from kinema.transport import from_dict

    package, resolved = _my_cell(tmp_path)
    context = BehaviorContext(node, config=resolved)
    pose = from_dict("geometry_msgs/msg/PoseStamped", {"header": {"frame_id": "world"}})
    from kinema.config.waypoint_location import waypoint_store_for

    store = waypoint_store_for(resolved)
    assert store is not None  # its copy of lab_sim's waypoints, in my_cell/waypoints/ (made at a save)
    targets = [
        package / "config" / "config.yaml",
        resolved.joint_limits_path,
        resolved.waypoints_path,
        Path(store.path),
    ]
    for target in targets:
        assert target is not None
        before = target.read_bytes() if target.exists() else None
        run = tick_behavior(
            behavior("SavePoseStampedToYaml"),
            {"message": pose, "yaml_filename": str(target.with_suffix(""))},
            context=context,
        )
        assert run.status == NodeStatus.FAILURE, target
        assert "refused by the robot rule" in run.toasts[-1], run.toasts
        assert (target.read_bytes() if target.exists() else None) == before
    beside = tick_behavior(
        behavior("SavePoseStampedToYaml"), {"message": pose, "yaml_filename": "my_pose"}, context=context
    )
    assert beside.status == NodeStatus.SUCCESS and (package / "objectives" / "my_pose.yaml").is_file()
