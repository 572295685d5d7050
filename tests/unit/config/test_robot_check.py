"""``kinema build`` as the robot's linter: every name that crosses a robot file is checked, at file:line."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import yaml

from kinema.cli.main import main
from kinema.config import Workspace, resolve_config
from kinema.config.robot_check import check_robot, robot_report
from kinema.config.robot_files import PackageIndex
from kinema.errors import ConfigError

LFS_POINTER = (
    "version https://git-lfs.github.com/spec/v1\n"
    "oid sha256:4d7a214614ab2935c943f9e0ff69d22eadbb8f32b1258daaa5e2ca24d17e2393\n"
    "size 12345\n"
)
MOVEIT_PRO = Path(__file__).resolve().parents[4] / "shared" / "compat" / "moveit_pro"
#: Text a user should never meet: a parser's own words instead of Kinema's.
PARSER_WORDS = (
    "XML parse error",
    "XMLSyntaxError",
    "ParseError",
    "mjParseXML",
    "Error opening file",
    "could not open",
    "pinocchio cannot",
    "buildModel",
    "Traceback",
    "resource not found",
)


def build(workspace: Path, config: str, capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    code = main(["build", "--skip-install", "-w", str(workspace), "-c", config])
    captured = capsys.readouterr()
    return code, captured.out + captured.err


@pytest.fixture
def lab_sim(tmp_path: Path) -> Path:
    """A workspace holding a copy of the bundled lab_sim (which overlays the bundled one)."""
    source = Workspace.discover().package("lab_sim").path
    shutil.copytree(source, tmp_path / "ws" / "src" / "lab_sim")
    return tmp_path / "ws"


def edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, f"{old!r} is not in {path}"
    path.write_text(text.replace(old, new, 1))


def line_of(path: Path, needle: str) -> int:
    return next(n for n, line in enumerate(path.read_text().splitlines(), 1) if needle in line)


def assert_problems(problems: list[ConfigError], *expected: tuple[Path, str | None, str]) -> None:
    """``problems`` are ``expected``, in order: (file, a text on the line it names or None, message start)."""
    messages = [str(p) for p in problems]
    assert len(messages) == len(expected), messages
    for message, (path, needle, start) in zip(messages, expected, strict=True):
        where = f"{path}:{line_of(path, needle)}" if needle is not None else str(path)
        assert message.startswith(f"{where}: {start}"), (message, where, start)


# -- robots that fit ------------------------------------------------------------------------------------


@pytest.mark.parametrize("config", ["lab_sim", "example_config"])
def test_the_bundled_robots_have_no_problems(config: str) -> None:
    report = robot_report(resolve_config(config))
    assert report.problems == [] and report.warnings == []
    assert {p.name for p in report.checked} >= {"lab_sim.urdf", "lab_sim.srdf", "lab_sim_scene.xml"}


def test_build_says_it_checked_the_robot(lab_sim: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out = build(lab_sim, "lab_sim", capsys)
    assert code == 0, out
    assert "checked the robot: 0 problems" in out


def test_a_panda_package_made_by_the_generator_has_no_problems(tmp_path: Path) -> None:
    share = PackageIndex().find("example-robot-data")
    if share is None:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data, in the test extra)")
    from kinema.scaffold.robot_package import new_robot_package

    robots = share / "robots" / "panda_description"
    root = tmp_path / "ws"
    (root / "src").mkdir(parents=True)
    new_robot_package(
        "panda_cell",
        robots / "urdf" / "panda.urdf",
        srdf=robots / "srdf" / "panda.srdf",
        workspace=Workspace.discover(root),
    )
    report = robot_report(resolve_config("panda_cell", Workspace.discover(root)))
    assert [str(p) for p in report.problems] == []
    assert len(report.checked) == 5  # URDF, MuJoCo scene, SRDF, joint limits, waypoints


def test_a_waypoint_inside_the_scenes_table_is_a_warning_at_its_line(tmp_path: Path) -> None:
    share = PackageIndex().find("example-robot-data")
    if share is None:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data, in the test extra)")
    from kinema.scaffold.robot_package import new_robot_package

    root = tmp_path / "ws"
    (root / "src").mkdir(parents=True)
    new_robot_package(
        "ur5_cell",
        share / "robots" / "ur_description" / "urdf" / "ur5_robot.urdf",
        workspace=Workspace.discover(root),
    )
    waypoints = root / "src" / "ur5_cell" / "waypoints" / "waypoints.yaml"
    data = yaml.safe_load(waypoints.read_text())
    into_table = {**data[0], "name": "IntoTable"}
    into_table["joint_state"] = {**data[0]["joint_state"], "position": [0.0, 1.2, 0.0, 0.0, 0.0, 0.0]}
    waypoints.write_text(yaml.safe_dump([*data, into_table], sort_keys=False))
    report = robot_report(resolve_config("ur5_cell", Workspace.discover(root)))
    assert [str(p) for p in report.problems] == []
    hits = [w for w in report.warnings if "in collision with the scene" in w]
    assert len(hits) == 1, report.warnings  # Home is clear of it
    assert hits[0].startswith(f"{waypoints}:{line_of(waypoints, 'IntoTable')}: waypoint 'IntoTable' is in")
    assert "upper_arm_link - table" in hits[0] and "ur5_cell_scene.xml" in hits[0]
    # A waypoint outside a joint's limits (an SRDF state the Kinova's URDF limits exclude) is said too.
    beyond = {**data[0], "name": "Beyond"}
    beyond["joint_state"] = {**data[0]["joint_state"], "position": [0.0, -1.0, 7.5, 0.0, 0.0, 0.0]}
    waypoints.write_text(yaml.safe_dump([*data, beyond], sort_keys=False))
    report = robot_report(resolve_config("ur5_cell", Workspace.discover(root)))
    (outside,) = [w for w in report.warnings if "outside its limits" in w]
    assert outside.startswith(
        f"{waypoints}:{line_of(waypoints, 'Beyond')}: waypoint 'Beyond' has elbow_joint = 7.5"
    )


# -- names that do not cross -----------------------------------------------------------------------------


def test_a_waypoint_naming_an_unknown_joint_fails_the_build(
    lab_sim: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    waypoints = lab_sim / "src" / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml"
    edit(waypoints, "shoulder_pan_joint", "shoulder_pan_jiont")
    code, out = build(lab_sim, "lab_sim", capsys)
    assert code == 1
    first = yaml.safe_load(waypoints.read_text())[0]["name"]
    line = line_of(waypoints, "    name:")  # the first waypoint's joint_state.name
    assert (
        f"{waypoints}:{line}: waypoint {first!r} names joint 'shoulder_pan_jiont' not in lab_sim.urdf; "
        "did you mean 'shoulder_pan_joint' or 'shoulder_lift_joint'? Valid: elbow_joint, linear_rail_joint, "
        "robotiq_85_left_finger_joint,"
    ) in out
    assert "checked the robot: 1 problem\n" in out and "build failed" in out


def test_a_waypoint_whose_names_and_positions_differ_in_count_is_one_error_said_once(
    lab_sim: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    waypoints = lab_sim / "src" / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml"
    data = yaml.safe_load(waypoints.read_text())
    first = data[0]
    first["joint_state"]["name"] = first["joint_state"]["name"][:-1]
    waypoints.write_text(yaml.safe_dump(data, sort_keys=False))
    code, out = build(lab_sim, "lab_sim", capsys)
    assert code == 1
    message = f"waypoint {first['name']!r} has "
    assert out.count(message) == 1, out
    assert "build failed: 1 error\n" in out


def test_a_controller_joint_no_actuator_drives_fails_the_build(
    lab_sim: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    config = lab_sim / "src" / "lab_sim" / "config" / "config.yaml"
    edit(
        config,
        "robot:\n",
        "robot:\n  controllers:\n    joint_trajectory_controller:\n"
        "      joints: [shoulder_pan_joint, robotiq_85_left_finger_joint]\n",
    )
    code, out = build(lab_sim, "lab_sim", capsys)
    assert code == 1
    line = line_of(config, "joints: [shoulder_pan_joint")
    assert (
        f"{config}:{line}: controller 'joint_trajectory_controller' commands joint "
        "'robotiq_85_left_finger_joint', which no actuator of the MuJoCo scene lab_sim_scene.xml drives"
    ) in out
    assert "actuators: linear_rail_joint, shoulder_pan_joint," in out
    assert "checked the robot: 1 problem\n" in out


def test_a_planning_group_the_srdf_lacks_fails_the_build(
    lab_sim: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    config = lab_sim / "src" / "lab_sim" / "config" / "config.yaml"
    edit(config, 'joint_group_name: "manipulator"', 'joint_group_name: "manipulater"')
    code, out = build(lab_sim, "lab_sim", capsys)
    assert code == 1
    line = line_of(config, "joint_group_name:")
    assert (
        f"{config}:{line}: the planning group 'manipulater' (moveit_params.joint_group_name) is not a " in out
    )
    assert "did you mean 'manipulator'?" in out


def test_every_srdf_name_is_checked_at_its_line(lab_sim: Path) -> None:
    srdf = lab_sim / "src" / "lab_sim" / "description" / "lab_sim.srdf"
    text = srdf.read_text()
    text = text.replace(
        "</robot>",
        (
            '  <group name="extra">\n'
            '    <joint name="elbow_jont"/>\n'
            '    <link name="no_such_link"/>\n'
            '    <chain base_link="tool0" tip_link="base_link"/>\n'
            '    <group name="nothing"/>\n'
            "  </group>\n"
            '  <group_state name="bent" group="extra"><joint name="elbow" value="1"/></group_state>\n'
            '  <end_effector name="hand" parent_link="tool_0" group="gripper"/>\n'
            '  <disable_collisions link1="base_link" link2="ghost" reason="Never"/>\n'
            '  <group_state name="groupless"><joint name="elbow_joint" value="1"/></group_state>\n'
            '  <end_effector name="no_parent" group="gripper"/>\n'
            "</robot>"
        ),
    )
    srdf.write_text(text)
    report = robot_report(resolve_config("lab_sim", Workspace.discover(lab_sim)))
    messages = [str(p) for p in report.problems]
    expected = [
        (
            line_of(srdf, "elbow_jont"),
            "<joint name='elbow_jont'>: 'elbow_jont' is not a joint of lab_sim.urdf; "
            "did you mean 'elbow_joint'?",
        ),
        (
            line_of(srdf, "no_such_link"),
            "<link name='no_such_link'>: 'no_such_link' is not a link of lab_sim.urdf",
        ),
        (
            line_of(srdf, 'tip_link="base_link"'),
            "group 'extra': the chain's tip 'base_link' is not below its base 'tool0' in the URDF",
        ),
        (line_of(srdf, '"nothing"'), "<group name='nothing'>: 'nothing' is not a group of the SRDF"),
        (line_of(srdf, '"elbow"'), "<joint name='elbow'>: 'elbow' is not a joint of lab_sim.urdf"),
        (
            line_of(srdf, "tool_0"),
            "<end_effector parent_link='tool_0'>: 'tool_0' is not a link of lab_sim.urdf; "
            "did you mean 'tool0'?",
        ),
    ]
    for line, message in expected:
        assert any(m.startswith(f"{srdf}:{line}: {message}") for m in messages), (message, messages)
    assert len(messages) == len(expected), messages
    # Elements without an attribute they need are skipped, as MoveIt skips them: a warning, not a problem.
    assert report.warnings == [
        f"{srdf}:{line_of(srdf, 'groupless')}: <group_state name='groupless'> names no group; its joint "
        "values are kept (MoveIt skips such a state)",
        f"{srdf}:{line_of(srdf, 'no_parent')}: <end_effector> has no 'parent_link' attribute; skipped, as "
        "MoveIt skips it",
        f"{srdf}:{line_of(srdf, 'ghost')}: <disable_collisions> names 'ghost', not a link of lab_sim.urdf; "
        "the pair is ignored",
    ]


def test_joint_limits_tool_frame_keyframe_and_sensor_site_are_checked(lab_sim: Path) -> None:
    package = lab_sim / "src" / "lab_sim"
    limits = package / "description" / "joint_limits.yaml"
    edit(limits, "wrist_3_joint:", "wrist_4_joint:")
    config = package / "config" / "config.yaml"
    edit(config, 'tool_frame: "grasp_link"', 'tool_frame: "grasp_lnk"')
    edit(config, 'mujoco_keyframe: "default"', 'mujoco_keyframe: "start"')
    edit(config, 'control_site: "grasp_site"', 'control_site: "grip_site"')
    scene = package / "description" / "lab_sim_scene.xml"
    assert_problems(
        check_robot(resolve_config("lab_sim", Workspace.discover(lab_sim))),
        (
            config,
            "mujoco_keyframe: ",
            f"the MuJoCo keyframe 'start' is not in the scene {scene}; valid: default, home",
        ),
        (
            limits,
            "wrist_4_joint",
            "joint_limits names joint 'wrist_4_joint', which is not a joint of lab_sim.urdf; did you mean "
            "'wrist_3_joint' or 'wrist_2_joint' or 'wrist_1_joint'? Valid: elbow_joint,",
        ),
        (config, "tool_frame: ", "robot.tool_frame 'grasp_lnk' is not a link of lab_sim.urdf; did you mean "),
        (
            config,
            "control_site: ",
            "the force/torque sensor's control_site 'grip_site' is not a site of the MuJoCo scene "
            "lab_sim_scene.xml; did you mean 'grasp_site'? Valid: ",
        ),
    )


def test_a_scene_missing_a_joint_is_told_before_the_controllers(lab_sim: Path) -> None:
    scene = lab_sim / "src" / "lab_sim" / "description" / "lab_sim_scene.xml"
    edit(scene, '<joint name="wrist_3_joint"', '<joint name="wrist_three_joint"')
    edit(scene, 'joint="wrist_3_joint"', 'joint="wrist_three_joint"')
    assert_problems(
        check_robot(resolve_config("lab_sim", Workspace.discover(lab_sim))),
        (
            scene,
            None,
            "the MuJoCo scene does not simulate joint 'wrist_3_joint' of lab_sim.urdf (no hinge or slide "
            "joint of that name); did you mean 'wrist_2_joint' or 'wrist_1_joint' or 'wrist_three_joint'? ",
        ),
    )


def test_a_urdf_the_planner_cannot_load_is_a_problem(lab_sim: Path) -> None:
    urdf = lab_sim / "src" / "lab_sim" / "description" / "lab_sim.urdf"
    edit(
        urdf,
        '<joint name="linear_rail_joint" type="prismatic">',
        '<joint name="linear_rail_joint" type="planar">',
    )
    assert_problems(
        check_robot(resolve_config("lab_sim", Workspace.discover(lab_sim))),
        (
            urdf,
            None,
            f"joint 'linear_rail_joint' in {urdf} has 4 coordinates; only revolute, continuous (planned "
            "within two turns) and prismatic joints are supported",
        ),
    )


# -- the scene's files, before MuJoCo reads them ----------------------------------------------------------


def test_a_scene_file_missing_or_an_lfs_pointer_is_told_by_kinema_not_mujoco(lab_sim: Path) -> None:
    description = lab_sim / "src" / "lab_sim" / "description"
    scene = description / "lab_sim_scene.xml"
    (description / "assets" / "bottle.stl").write_text(LFS_POINTER)
    (description / "assets" / "text.stl").write_text("solid t\nendsolid t\n")
    edit(
        scene,
        "<asset>",
        '<include file="parts/gone.xml"/>\n  <asset><mesh file="assets/bottle.stl"/>\n'
        '    <mesh file="assets/text.stl"/>',
    )
    messages = [str(p) for p in check_robot(resolve_config("lab_sim", Workspace.discover(lab_sim)))]
    include_line = line_of(scene, "parts/gone.xml")
    bottle_line = line_of(scene, "bottle.stl")
    assert messages == [
        f"{scene}:{include_line}: include file 'parts/gone.xml' not found (looked for "
        f"{description / 'parts' / 'gone.xml'})",
        f"{scene}:{line_of(scene, 'text.stl')}: mesh {description / 'assets' / 'text.stl'} is a text STL, "
        "which MuJoCo cannot read: save it as binary STL or OBJ",
        f"{scene}:{bottle_line}: mesh {description / 'assets' / 'bottle.stl'} is a Git LFS pointer file "
        "(run `git lfs pull`)",
    ]


def test_an_include_is_found_in_a_packages_mujoco_assets(lab_sim: Path) -> None:
    """MoveIt Pro's layout: a scene includes picknik_accessories/mujoco_assets' files by their path there."""
    accessories = lab_sim / "src" / "accessories"
    (accessories / "mujoco_assets" / "props").mkdir(parents=True)
    (accessories / "package.xml").write_text("<package format='3'><name>accessories</name></package>")
    (accessories / "mujoco_assets" / "props" / "props.xml").write_text(
        '<mujoco><asset><mesh name="prop" file="props/prop.stl"/></asset>'
        '<worldbody><body name="prop" pos="3 3 0"><geom type="mesh" mesh="prop"/></body></worldbody></mujoco>'
    )
    assets = lab_sim / "src" / "lab_sim" / "description" / "assets"
    shutil.copy(assets / "cube_0_5.stl", accessories / "mujoco_assets" / "props" / "prop.stl")
    scene = lab_sim / "src" / "lab_sim" / "description" / "lab_sim_scene.xml"
    edit(scene, "</mujoco>", '<include file="props/props.xml"/>\n</mujoco>')
    assert check_robot(resolve_config("lab_sim", Workspace.discover(lab_sim))) == []
    # The simulation driver, kinema view and the planning scene load it by the same rule (they gave
    # MuJoCo's "Error opening file 'props/props.xml'" where the build was happy).
    import mujoco

    from kinema.config.mujoco_scene import load_scene

    model = load_scene(scene)
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "prop") >= 0


# -- MoveIt Pro's own lab_sim, as a clone without `git lfs pull` has it -------------------------------------


@pytest.fixture
def moveit_pro_workspace(tmp_path: Path) -> Path:
    packages = MOVEIT_PRO / "packages" / "src"
    if not packages.is_dir():
        pytest.skip(f"MoveIt Pro's reference packages are not at {packages} (../shared beside the checkout)")
    src = tmp_path / "ws" / "src"
    shutil.copytree(packages, src)
    # The objectives and waypoints of the same commit are kept beside the packages (see its README).
    for name in ("objectives", "waypoints"):
        shutil.copytree(MOVEIT_PRO / "lab_sim" / name, src / "lab_sim" / name)
    shutil.copytree(
        MOVEIT_PRO / "picknik_ur_base_config" / "objectives",
        src / "moveit_pro_ur_configs" / "picknik_ur_base_config" / "objectives",
    )
    return tmp_path / "ws"


def test_moveit_pro_lab_sim_stops_at_the_lfs_pointers_and_absent_packages(
    moveit_pro_workspace: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    resolved = resolve_config("lab_sim", Workspace.discover(moveit_pro_workspace))
    # The whole chain was read: the parent's config, its !degrees joint limits, the ros2_control yaml,
    # the xacro with urdf_params.
    assert resolved.chain == ["picknik_ur_base_config", "lab_sim"]
    assert resolved.urdf_params["mujoco_model"] == "description/scene.xml"
    # kinema run starts the simulation for it (urdf_params names the scene), which stops at the same
    # first problem: it ran with no simulation at all, and every motion waited for controllers in vain.
    from kinema.config.mujoco_scene import load_scene
    from kinema.drivers.registry import drivers_for_config

    assert [spec.name for spec in drivers_for_config(resolved)] == ["mujoco"]
    # Its gripper comes from what MoveIt Pro's files say (the controller's joint, the SRDF's open and
    # close states), not from a Kinema-only robot.gripper section.
    from kinema.config.cell import CellSettings, GripperConfig

    assert CellSettings.from_config(resolved).gripper == GripperConfig(
        "robotiq_gripper_controller", "robotiq_85_left_knuckle_joint", 0.05, 0.79
    )
    model_path = resolved.mujoco_model_path
    assert model_path is not None
    with pytest.raises(ConfigError, match=r"is a Git LFS pointer file \(run `git lfs pull`\) \(and \d+ more"):
        load_scene(model_path)
    code, out = build(moveit_pro_workspace, "lab_sim", capsys)
    assert code == 1
    robot = out[out.index("TreeNodesModel for Groot2") :]
    src = moveit_pro_workspace / "src"
    assert f"{src / 'lab_sim' / 'description' / 'picknik_ur.xacro'}: " in robot
    assert "ROS package 'ur_description' not found, needed by " in robot
    assert "ROS package 'robotiq_description' not found, needed by " in robot
    assets = src / "picknik_accessories" / "mujoco_assets" / "assets"
    pointer = f"{src / 'picknik_accessories' / 'mujoco_assets' / 'ur5e' / 'ur5e_globals.xml'}:"
    assert (
        f"{pointer}{line_of(Path(pointer[:-1]), 'assets/base.stl')}: mesh {assets / 'base.stl'} is a Git LFS "
        "pointer file (run `git lfs pull`)" in robot
    )
    assert "more files the MuJoCo scene names are Git LFS pointer files (run `git lfs pull`)" in robot
    # Kinema's own words only: no parser of MuJoCo, pinocchio or XML spoke.
    for words in PARSER_WORDS:
        assert words.lower() not in out.lower(), words
    # The robot's names themselves fit: no SRDF, joint limits or waypoint complaints.
    assert "picknik_ur.srdf" not in robot and "joint_limits.yaml" not in robot and "waypoints" not in robot
    assert "robot.gripper" not in out
