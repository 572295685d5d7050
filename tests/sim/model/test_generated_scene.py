"""kinema.scaffold.mjcf_scene: a URDF becomes a scene that loads, holds its keyframes and is collision-free.

The Panda (DAE visuals, STL collisions, a mimic finger, massless frames) and the UR5 (a ``world`` root link)
from example-robot-data, plus a small hand-written URDF for the cases they do not have.
"""

from __future__ import annotations

import shutil
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
import pytest

from kinema.config.robot_files import (
    PackageIndex,
    ResolvedRobot,
    convert_mesh,
    converted_mesh_rgba,
    resolve_robot,
)
from kinema.errors import ScaffoldError
from kinema.scaffold.mjcf_scene import (
    COLLISION_GROUP,
    NATURAL_FREQUENCY,
    VISUAL_GROUP,
    adjacent_link_pairs,
    generate_scene,
    longest_chain,
)

PANDA_HOME = {
    "panda_joint1": 0.0,
    "panda_joint2": -0.785,
    "panda_joint3": 0.0,
    "panda_joint4": -2.356,
    "panda_joint5": 0.0,
    "panda_joint6": 1.571,
    "panda_joint7": 0.785,
    "panda_finger_joint1": 0.035,
}
UR5_HOME = {
    "shoulder_pan_joint": 0.0,
    "shoulder_lift_joint": -1.57,
    "elbow_joint": 1.57,
    "wrist_1_joint": -1.57,
    "wrist_2_joint": -1.57,
    "wrist_3_joint": 0.0,
}
# The xArm7's URDF gives every joint friction (1 N·m) and damping (2-10 N·m·s/rad).
XARM7_HOME = {f"joint{i}": 0.0 for i in range(1, 8)} | {"joint2": -0.5, "joint4": 0.6, "joint6": 1.1}
ROBOTS = {
    "panda": ("panda_description/urdf/panda.urdf", PANDA_HOME),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", UR5_HOME),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", XARM7_HOME),
}


@dataclass
class Generated:
    robot: ResolvedRobot
    scene: Path
    home: Mapping[str, float]
    model: mujoco.MjModel


@pytest.fixture(scope="module")
def example_robots() -> Path:
    share = PackageIndex(environ={}).find("example-robot-data")
    if share is None:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data)")
    return share / "robots"


@pytest.fixture(scope="module")
def mesh_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("mesh_cache")


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def generated(
    request: pytest.FixtureRequest,
    example_robots: Path,
    mesh_cache: Path,
    tmp_path_factory: pytest.TempPathFactory,
) -> Generated:
    relative, home = ROBOTS[request.param]
    robot = resolve_robot(example_robots / relative, index=PackageIndex(environ={}))
    out = tmp_path_factory.mktemp(request.param)
    scene = generate_scene(robot, out, home=home, keyframes={"zero": {}}, mesh_cache=mesh_cache)
    return Generated(robot, scene, home, mujoco.MjModel.from_xml_path(str(scene)))


def at_keyframe(model: mujoco.MjModel, name: str) -> mujoco.MjData:
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key(name).id)
    mujoco.mj_forward(model, data)
    return data


def robot_links(robot: ResolvedRobot) -> set[str]:
    from lxml import etree

    root = etree.fromstring(robot.urdf_text.encode())
    # A link named "world" is MuJoCo's world body (the UR5's fixed mount).
    return {link.get("name") for link in root.findall("link")} - {"world"}


# -- the robot ------------------------------------------------------------------------------------------


def test_every_link_is_a_body_named_like_it_with_gravity_compensated(generated: Generated) -> None:
    model = generated.model
    bodies = {model.body(i).name: i for i in range(model.nbody)}
    links = robot_links(generated.robot)
    assert links <= set(bodies), f"links missing as bodies: {links - set(bodies)}"
    root = longest_chain(generated.robot.urdf_text)[0]
    root_id = bodies[root]
    assert model.body_parentid[root_id] == 0, "the robot's base is a body of its own under the world"
    assert model.body_jntnum[root_id] == 0, "the base is fixed"
    for link in links:
        assert model.body_gravcomp[bodies[link]] == 1.0, link


def test_visual_meshes_show_and_collision_meshes_collide(generated: Generated, mesh_cache: Path) -> None:
    model = generated.model
    for reference in generated.robot.meshes:
        body = model.body(reference.link).id
        geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] == body]
        mesh_geoms = [g for g in geoms if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH]
        if reference.role == "visual":
            visual = [g for g in mesh_geoms if model.geom_group[g] == VISUAL_GROUP]
            assert visual, f"{reference.link}: no visual mesh geom"
            for g in visual:
                assert model.geom_contype[g] == 0 and model.geom_conaffinity[g] == 0
            expected = converted_mesh_rgba(convert_mesh(reference.path, mesh_cache))
            if expected is not None:
                colours = [tuple(model.geom_rgba[g]) for g in visual]
                assert any(c == pytest.approx(expected, abs=1e-3) for c in colours), reference.link
        else:
            collision = [g for g in mesh_geoms if model.geom_group[g] == COLLISION_GROUP]
            assert collision, f"{reference.link}: no collision mesh geom"
            for g in collision:
                assert model.geom_contype[g] != 0 and model.geom_conaffinity[g] != 0


def test_the_scene_folder_is_portable_and_holds_no_collada(generated: Generated, tmp_path: Path) -> None:
    from lxml import etree

    folder = generated.scene.parent
    referenced = {m.get("file") for m in etree.parse(str(generated.scene)).getroot().iter("mesh")}
    assert {p.name for p in (folder / "meshes").iterdir()} == referenced, "meshes/ holds what the scene uses"
    assert not [name for name in referenced if not name.endswith((".obj", ".stl"))]
    moved = tmp_path / "elsewhere"
    shutil.copytree(folder, moved)
    shutil.rmtree(folder / "meshes")
    try:
        model = mujoco.MjModel.from_xml_path(str(moved / generated.scene.name))
    finally:
        shutil.copytree(moved / "meshes", folder / "meshes")
    assert model.nmesh == generated.model.nmesh > 0


def test_one_position_actuator_per_independent_joint(generated: Generated) -> None:
    model = generated.model
    joints = {j.name: j for j in generated.robot.joints() if j.movable}
    independent = [name for name, j in joints.items() if j.mimic is None]
    assert [model.actuator(i).name for i in range(model.nu)] == independent
    from lxml import etree

    written = etree.parse(str(generated.scene)).getroot().find("actuator")
    assert [(a.tag, a.get("name")) for a in written] == [("position", name) for name in independent]
    for i, name in enumerate(independent):
        joint = joints[name]
        assert model.actuator_trntype[i] == mujoco.mjtTrn.mjTRN_JOINT
        assert model.joint(int(model.actuator_trnid[i, 0])).name == name
        kp, kv = model.actuator_gainprm[i, 0], -model.actuator_biasprm[i, 2]
        assert kp > 0
        assert kv / kp == pytest.approx(2.0 / NATURAL_FREQUENCY, rel=1e-4), "critically damped at ω"
        assert model.actuator_biasprm[i, 1] == -kp
        assert tuple(model.actuator_ctrlrange[i]) == pytest.approx((joint.lower, joint.upper))
        assert tuple(model.actuator_forcerange[i]) == pytest.approx((-joint.effort, joint.effort))


def test_mimic_joints_are_equality_constraints(generated: Generated) -> None:
    model = generated.model
    mimics = [j for j in generated.robot.joints() if j.mimic is not None]
    couplings = {}
    for e in range(model.neq):
        if model.eq_type[e] == mujoco.mjtEq.mjEQ_JOINT:
            follower, leader = (
                model.joint(int(model.eq_obj1id[e])).name,
                model.joint(int(model.eq_obj2id[e])).name,
            )
            couplings[(follower, leader)] = model.eq_data[e][:5]
    assert len(couplings) == len(mimics)
    for joint in mimics:
        leader, multiplier, offset = joint.mimic  # type: ignore[misc]
        assert couplings[(joint.name, leader)].tolist() == pytest.approx([offset, multiplier, 0, 0, 0])


# -- the world --------------------------------------------------------------------------------------------


def test_the_robot_stands_on_a_table_with_room_in_front(generated: Generated) -> None:
    model = generated.model
    data = at_keyframe(model, "home")
    base = model.body(longest_chain(generated.robot.urdf_text)[0]).id
    assert data.xpos[base].tolist() == pytest.approx([0.0, 0.0, 0.0])
    table = model.body("table").id
    (box,) = [g for g in range(model.ngeom) if model.geom_bodyid[g] == table]
    low = data.geom_xpos[box] - model.geom_size[box]
    high = data.geom_xpos[box] + model.geom_size[box]
    assert high[2] == pytest.approx(0.0), "the table top is where the base stands"
    assert low[0] < -0.1 and high[0] > 0.5, "the table reaches from under the base to in front of it"
    assert low[1] < -0.4 and high[1] > 0.4
    floor = model.geom("floor").id
    assert model.geom_type[floor] == mujoco.mjtGeom.mjGEOM_PLANE
    assert data.geom_xpos[floor][2] == pytest.approx(low[2]), "the table stands on the floor"
    assert model.nlight >= 1


def test_the_scene_camera_sees_the_robot_from_the_front(generated: Generated) -> None:
    model = generated.model
    data = at_keyframe(model, "home")
    camera = model.camera("scene_camera").id
    position, rotation = data.cam_xpos[camera], data.cam_xmat[camera].reshape(3, 3)
    assert position[0] > 0.5, "in front of the robot (its +x)"
    half_fov = np.radians(model.cam_fovy[camera]) / 2
    for body in range(1, model.nbody):
        if model.body(body).name in robot_links(generated.robot):
            seen = rotation.T @ (data.xpos[body] - position)  # camera frame: looks along -z
            assert seen[2] < 0, model.body(body).name
            assert abs(seen[1] / seen[2]) < np.tan(half_fov), f"{model.body(body).name} is out of the picture"


# -- keyframes and holding them ---------------------------------------------------------------------------


def test_keyframes_set_qpos_and_ctrl(generated: Generated) -> None:
    model = generated.model
    joints = {j.name: j for j in generated.robot.joints() if j.movable}
    for key in ("home", "zero"):
        data = at_keyframe(model, key)
        for name, joint in joints.items():
            if joint.mimic is not None:
                leader, multiplier, offset = joint.mimic
                expected = offset + multiplier * data.joint(leader).qpos[0]
            elif key == "home":
                expected = generated.home.get(name, 0.0)
            else:  # not given: 0, clipped into the joint's limits (the Panda's joint 4 cannot reach 0)
                expected = float(np.clip(0.0, joint.lower, joint.upper))
            assert data.joint(name).qpos[0] == pytest.approx(expected), (key, name)
            if joint.mimic is None:
                assert data.actuator(name).ctrl[0] == pytest.approx(expected), (key, name)


def test_the_robot_holds_home_for_two_seconds(generated: Generated) -> None:
    model = generated.model
    data = at_keyframe(model, "home")
    start = data.qpos.copy()
    while data.time < 2.0:
        mujoco.mj_step(model, data)
    worst = np.abs(data.qpos - start).max()
    assert worst < 0.01, f"drifted {worst:.4f} rad/m from home"


def test_each_joint_follows_a_ramp_and_settles(generated: Generated) -> None:
    """The servo rule gives tracking a planner can rely on: lag ≈ 2·v/ω on a ramp, settled soon after."""
    model = generated.model
    for actuator in range(model.nu):
        data = at_keyframe(model, "home")
        joint = int(model.actuator_trnid[actuator, 0])
        address = model.jnt_qposadr[joint]
        high = model.actuator_ctrlrange[actuator][1] if model.actuator_ctrllimited[actuator] else np.inf
        revolute = model.jnt_type[joint] == mujoco.mjtJoint.mjJNT_HINGE
        speed = 0.3 if revolute else 0.01  # rad/s or m/s, for one second
        start = float(data.ctrl[actuator])
        if start + speed > high:
            speed = -speed
        worst_lag = 0.0
        while data.time < 1.5:
            data.ctrl[actuator] = start + speed * min(data.time, 1.0)
            mujoco.mj_step(model, data)
            worst_lag = max(worst_lag, abs(data.qpos[address] - data.ctrl[actuator]))
        name = model.actuator(actuator).name
        assert worst_lag < 3.0 * abs(speed) / NATURAL_FREQUENCY, f"{name} lags {worst_lag:.4f}"
        assert abs(data.qpos[address] - (start + speed)) < 0.002, f"{name} did not settle"
        assert data.ncon == 0 or all(
            model.geom_bodyid[c.geom1] != model.body("table").id for c in data.contact[: data.ncon]
        ), f"{name}'s ramp ran into the table: pick another"


def test_home_is_collision_free(generated: Generated) -> None:
    model = generated.model
    data = at_keyframe(model, "home")
    adjacent = adjacent_link_pairs(generated.robot.urdf_text)
    touching = []
    for contact in data.contact[: data.ncon]:
        a = model.body(model.geom_bodyid[contact.geom1]).name
        b = model.body(model.geom_bodyid[contact.geom2]).name
        if frozenset((a, b)) not in adjacent:
            touching.append((a, b, float(contact.dist)))
    assert touching == []


def test_a_pose_reaching_into_the_table_touches_it(generated: Generated) -> None:
    """The home check above can fail: the robot's collision meshes do collide with the table."""
    model = generated.model
    data = at_keyframe(model, "home")
    lifts = {"panda_joint2": 1.7, "shoulder_lift_joint": 0.6, "joint2": 1.9}
    lift = next(name for name in lifts if name in generated.home)
    data.joint(lift).qpos[0] = lifts[lift]
    mujoco.mj_forward(model, data)
    table = model.body("table").id
    touching = {
        body
        for c in data.contact[: data.ncon]
        for body in (model.geom_bodyid[c.geom1], model.geom_bodyid[c.geom2])
    }
    assert table in touching


def test_a_keyframe_naming_an_unknown_joint_is_refused(
    example_robots: Path, mesh_cache: Path, tmp_path: Path
) -> None:
    robot = resolve_robot(example_robots / ROBOTS["ur5"][0], index=PackageIndex(environ={}))
    with pytest.raises(ScaffoldError, match=r"'elbow'.* did you mean 'elbow_joint'"):
        generate_scene(robot, tmp_path, home={"elbow": 1.0}, mesh_cache=mesh_cache)


# -- planning group guess ---------------------------------------------------------------------------------


def test_longest_chain_of_the_example_robots(example_robots: Path) -> None:
    panda = resolve_robot(example_robots / ROBOTS["panda"][0], index=PackageIndex(environ={}))
    assert longest_chain(panda.urdf_text) == (
        "panda_link0",
        "panda_hand_tcp",
        [f"panda_joint{i}" for i in range(1, 8)],
    )
    ur5 = resolve_robot(example_robots / ROBOTS["ur5"][0], index=PackageIndex(environ={}))
    base, tip, joints = longest_chain(ur5.urdf_text)
    assert (base, tip) == ("base_link", "ee_link")
    assert joints == list(UR5_HOME)
    # Baxter's hand carries a camera, a range sensor and an accelerometer beside its gripper: the tip goes
    # on only into the gripper (it ended at the hand camera, the first child in the file).
    baxter = resolve_robot(
        example_robots / "baxter_description" / "urdf" / "baxter.urdf", index=PackageIndex(environ={})
    )
    base, tip, joints = longest_chain(baxter.urdf_text)
    assert tip == "right_gripper" and joints[0] == "right_s0" and len(joints) == 7
    # Mobile manipulators: the arm, from the torso where the head branches off (a wheel's two joints won
    # before), to the strongest tool point (the PR2's palm carries an led_frame beside its tool_frame).
    for urdf, first, expected_tip in (
        ("tiago_description/robots/tiago.urdf", "arm_1_joint", "hand_tool_link"),
        ("pr2_description/urdf/pr2.urdf", "r_shoulder_pan_joint", "r_gripper_tool_frame"),
    ):
        robot = resolve_robot(example_robots / urdf, index=PackageIndex(environ={}))
        base, tip, joints = longest_chain(robot.urdf_text)
        assert (base, joints[0], tip, len(joints)) == ("torso_lift_link", first, expected_tip, 7)


def test_inertias_no_rigid_body_has_are_repaired_and_said(
    example_robots: Path, mesh_cache: Path, tmp_path: Path
) -> None:
    """The PR2's and TIAGo's URDFs have inertias MuJoCo refuses ("inertia must satisfy A + B >= C",
    "must have positive eigenvalues"): the scene was not made at all."""
    robot = resolve_robot(example_robots / "pr2_description/urdf/pr2.urdf", index=PackageIndex(environ={}))
    notes: list[str] = []
    scene = generate_scene(robot, tmp_path, home={}, mesh_cache=mesh_cache, notes=notes)
    assert mujoco.MjModel.from_xml_path(str(scene)).nbody > 50
    (note,) = [n for n in notes if "inertia no rigid body has" in n]
    assert "sensor_mount_link" in note
    # TIAGo's written scene, its inertias rounded, still loads (arm_1_link is at the edge of A + B >= C).
    tiago = resolve_robot(
        example_robots / "tiago_description/robots/tiago.urdf", index=PackageIndex(environ={})
    )
    scene = generate_scene(tiago, tmp_path / "tiago", home={}, mesh_cache=mesh_cache)
    assert mujoco.MjModel.from_xml_path(str(scene)).body("arm_1_link").id > 0


def test_adjacent_links_are_one_joint_apart_once_fixed_joints_merge(example_robots: Path) -> None:
    panda = resolve_robot(example_robots / ROBOTS["panda"][0], index=PackageIndex(environ={}))
    adjacent = adjacent_link_pairs(panda.urdf_text)
    assert frozenset(("panda_link7", "panda_hand")) in adjacent  # through the fixed link8
    assert frozenset(("panda_hand", "panda_leftfinger")) in adjacent
    assert frozenset(("panda_leftfinger", "panda_rightfinger")) not in adjacent
    assert frozenset(("panda_link5", "panda_link7")) not in adjacent


# -- what the example robots do not have -------------------------------------------------------------------

SMALL_ROBOT = """<?xml version="1.0"?>
<robot name="small">
  <material name="blue"><color rgba="0.1 0.2 0.9 1"/></material>
  <link name="mount">
    <visual><geometry><box size="0.2 0.2 0.05"/></geometry><material name="blue"/></visual>
  </link>
  <link name="arm">
    <visual><origin xyz="0 0 0.2"/><geometry><cylinder radius="0.03" length="0.4"/></geometry>
      <material name="orange"><color rgba="1 0.5 0 1"/></material></visual>
    <collision><origin xyz="0 0 0.2"/><geometry><cylinder radius="0.03" length="0.4"/></geometry></collision>
    <inertial>
      <origin xyz="0 0 0.2"/><mass value="1"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.001" ixy="0" ixz="0" iyz="0"/>
    </inertial>
  </link>
  <link name="no_inertia"/>
  <link name="left">
    <inertial><mass value="0.05"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/>
    </inertial>
  </link>
  <link name="right">
    <inertial><mass value="0.05"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/>
    </inertial>
  </link>
  <joint name="swing" type="revolute">
    <parent link="mount"/><child link="arm"/><origin xyz="0 0 0.05"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="20" velocity="1"/>
  </joint>
  <joint name="twist" type="continuous">
    <parent link="arm"/><child link="no_inertia"/><origin xyz="0 0 0.4"/><axis xyz="0 0 1"/>
  </joint>
  <joint name="left_slide" type="prismatic">
    <parent link="no_inertia"/><child link="left"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.05" effort="5" velocity="0.1"/>
  </joint>
  <joint name="right_slide" type="prismatic">
    <parent link="no_inertia"/><child link="right"/><axis xyz="0 1 0"/>
    <limit lower="-0.06" upper="0.01" effort="5" velocity="0.1"/>
    <mimic joint="left_slide" multiplier="-1" offset="0.01"/>
  </joint>
</robot>
"""


def test_a_robot_without_meshes_inertia_or_limits(tmp_path: Path) -> None:
    urdf = tmp_path / "small.urdf"
    urdf.write_text(SMALL_ROBOT)
    robot = resolve_robot(urdf, index=PackageIndex(environ={}, site_packages=[]))
    scene = generate_scene(robot, tmp_path / "out", name="cell", home={"swing": 0.3, "left_slide": 0.02})
    assert scene.name == "cell_scene.xml"
    model = mujoco.MjModel.from_xml_path(str(scene))

    mount = model.body("mount").id
    assert mount > 0 and model.body_mass[mount] == 0.0, "a static massless root stays a body as it is"
    assert model.body_mass[model.body("no_inertia").id] > 0, "a moving body gets a tiny mass"
    mount_visual = [g for g in range(model.ngeom) if model.geom_bodyid[g] == mount]
    assert [tuple(model.geom_rgba[g]) for g in mount_visual] == [pytest.approx((0.1, 0.2, 0.9, 1))]
    arm_visual = [
        g
        for g in range(model.ngeom)
        if model.geom_bodyid[g] == model.body("arm").id and model.geom_group[g] == VISUAL_GROUP
    ]
    assert [tuple(model.geom_rgba[g]) for g in arm_visual] == [pytest.approx((1, 0.5, 0, 1))]

    assert [model.actuator(i).name for i in range(model.nu)] == ["swing", "twist", "left_slide"]
    assert not model.actuator_ctrllimited[model.actuator("twist").id], "a continuous joint has no ctrlrange"
    assert not model.actuator_forcelimited[model.actuator("twist").id], "nor a force limit without an effort"

    data = at_keyframe(model, "home")
    assert data.joint("right_slide").qpos[0] == pytest.approx(0.01 - 0.02)
    start = data.qpos.copy()
    while data.time < 2.0:
        mujoco.mj_step(model, data)
    assert np.abs(data.qpos - start).max() < 0.01
    assert longest_chain(robot.urdf_text) == ("mount", "no_inertia", ["swing", "twist"])


def test_a_robot_mounted_on_a_world_link_stands_on_the_table_where_its_mount_is(tmp_path: Path) -> None:
    mounted = SMALL_ROBOT.replace(
        '<link name="mount">',
        '<link name="world"/><joint name="world_joint" type="fixed"><parent link="world"/>'
        '<child link="mount"/><origin xyz="0.5 0.2 0.1"/></joint>\n  <link name="mount">',
    )
    urdf = tmp_path / "mounted.urdf"
    urdf.write_text(mounted)
    robot = resolve_robot(urdf, index=PackageIndex(environ={}, site_packages=[]))
    model = mujoco.MjModel.from_xml_path(str(generate_scene(robot, tmp_path / "out")))
    data = at_keyframe(model, "home")
    assert data.xpos[model.body("mount").id].tolist() == pytest.approx([0.5, 0.2, 0.1])
    table = model.geom("table").id
    top = data.geom_xpos[table] + model.geom_size[table]
    low = data.geom_xpos[table] - model.geom_size[table]
    assert top[2] == pytest.approx(0.1)
    assert low[0] < 0.5 < top[0] and low[1] < 0.2 < top[1]
    assert data.ncon == 0


def test_links_whose_hulls_overlap_at_home_do_not_push_each_other(
    example_robots: Path, mesh_cache: Path, tmp_path: Path
) -> None:
    """MuJoCo collides meshes as convex hulls: Baxter's lower shoulders overlap its torso at Home, pushed
    the arm 0.36 rad away from it and made every trajectory miss its tolerance. The scene excludes those
    contacts and says so."""
    robot = resolve_robot(
        example_robots / "baxter_description" / "urdf" / "baxter.urdf", index=PackageIndex(environ={})
    )
    notes: list[str] = []
    scene = generate_scene(robot, tmp_path, home={}, mesh_cache=mesh_cache, notes=notes)
    assert any("right_lower_shoulder - torso" in note for note in notes), notes
    model = mujoco.MjModel.from_xml_path(str(scene))
    data = at_keyframe(model, "home")
    while data.time < 1.0:
        mujoco.mj_step(model, data)
    assert abs(data.joint("right_s0").qpos[0]) < 0.01, data.joint("right_s0").qpos
