"""The lab_sim description files: one source of truth, URDF and MJCF agree, the scene suits a driver."""

from __future__ import annotations

import runpy

import numpy as np
import pytest
import yaml

from kinema.motion import frame_poses
from kinema.resources import bundled_dir

ARM = (
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
GRIPPER = "robotiq_85_left_knuckle_joint"

LAB_SIM = bundled_dir("configs") / "lab_sim"


def test_committed_files_are_what_the_generator_writes(description):
    gen = runpy.run_path(str(LAB_SIM / "description" / "generate.py"))
    assert description.urdf.read_text() == gen["render_urdf"](), "run configs/lab_sim/description/generate.py"
    assert description.mjcf.read_text() == gen["render_scene"](), (
        "run configs/lab_sim/description/generate.py"
    )
    folder = LAB_SIM / "description"
    assert (folder / gen["APRILTAGS_FILE"]).read_text() == gen["render_apriltags"](), (
        "run configs/lab_sim/description/generate.py"
    )
    for tag_id in {o.tag_id for o in gen["TAGGED_OBJECTS"]} | {gen["TRAY_TAG_ID"]}:
        texture = folder / "textures" / f"{gen['tag_texture'](tag_id)}.png"
        assert texture.read_bytes() == gen["tag_texture_png"](tag_id), f"{texture}: run generate.py"


def _mujoco_qpos(cell, model, q):
    """MuJoCo qpos for planning configuration q (mimic fingers filled in), objects left where they are."""
    pq = model.pin_configuration(q)
    qpos = cell.d.qpos.copy()
    for name in (*ARM, GRIPPER, "robotiq_85_left_finger_joint", "robotiq_85_right_finger_joint"):
        jid = model.pin_model.getJointId(name)
        qpos[cell.m.jnt_qposadr[cell.m.joint(name).id]] = pq[model.pin_model.idx_qs[jid]]
    return qpos


def test_committed_perception_objects_are_what_their_generator_writes(tmp_path):
    objects = runpy.run_path(str(LAB_SIM / "description" / "perception_objects.py"))
    assert objects["TABLE_TOP"] == runpy.run_path(str(LAB_SIM / "description" / "generate.py"))["TABLE_TOP"]
    included = LAB_SIM / "description" / "lab_sim_perception_objects.xml"
    assert included.read_text() == objects["render_objects"](), (
        "run configs/lab_sim/description/perception_objects.py"
    )
    for shape in (objects["BOTTLE"], objects["MICROSCOPE"], objects["CUBE"]):
        fresh = tmp_path / shape.stl
        objects["write_stl"](shape, fresh)
        committed = LAB_SIM / "description" / "assets" / shape.stl
        assert committed.read_bytes() == fresh.read_bytes(), (
            f"run perception_objects.py ({shape.stl} differs)"
        )


def test_forward_kinematics_of_urdf_and_mjcf_agree(description, cell):
    """100 random configurations: every link's pose from pinocchio (URDF) matches MuJoCo (MJCF) to 1e-6."""
    import mujoco

    model = description.load_model()
    rng = np.random.default_rng(42)
    data = model.new_data()
    compared = 0
    for _ in range(100):
        q = rng.uniform(model.lower, model.upper)
        cell.d.qpos[:] = _mujoco_qpos(cell, model, q)
        mujoco.mj_kinematics(cell.m, cell.d)
        for link, T in frame_poses(model, q, data).items():
            if link == "world" or mujoco.mj_name2id(cell.m, mujoco.mjtObj.mjOBJ_BODY, link) < 0:
                continue
            body = cell.d.body(link)
            assert np.abs(body.xpos - T[:3, 3]).max() < 1e-6, link
            assert np.abs(body.xmat.reshape(3, 3) - T[:3, :3]).max() < 1e-6, link
            compared += 1
    assert compared >= 100 * 14


def test_collision_geoms_of_urdf_and_mjcf_agree(description, cell):
    """Same primitives at the same places: the planner checks what the simulator simulates."""
    import mujoco
    import pinocchio as pin

    model = description.load_model()
    geoms = pin.buildGeomFromUrdf(model.pin_model, str(description.urdf), pin.GeometryType.COLLISION)
    q = model.configuration({"shoulder_lift_joint": -1.2, "elbow_joint": 1.3, "wrist_2_joint": 0.7})
    data, gdata = model.new_data(), pin.GeometryData(geoms)
    pin.updateGeometryPlacements(model.pin_model, data, geoms, gdata, model.pin_configuration(q))
    cell.d.qpos[:] = _mujoco_qpos(cell, model, q)
    mujoco.mj_kinematics(cell.m, cell.d)
    urdf_centres = sorted(tuple(np.round(p.translation, 6)) for p in gdata.oMg)
    robot_bodies = {cell.m.body(model_link).id for model_link in model.link_names if model_link != "world"}
    mj_centres = sorted(
        tuple(np.round(cell.d.geom_xpos[g], 6))
        for g in range(cell.m.ngeom)
        if cell.m.geom_bodyid[g] in robot_bodies and cell.m.geom_contype[g] != 0
    )
    assert len(urdf_centres) == len(mj_centres) == 16
    assert np.abs(np.array(urdf_centres) - np.array(mj_centres)).max() < 1e-6


def test_scene_is_ready_for_a_driver(cell):
    import mujoco

    m = cell.m
    assert m.opt.timestep == pytest.approx(0.002)
    assert {m.actuator(i).name for i in range(m.nu)} == {*ARM, GRIPPER}  # one position servo per joint
    assert m.actuator(GRIPPER).ctrlrange.tolist() == pytest.approx([0.0, 0.7929])
    assert {m.key(i).name for i in range(m.nkey)} >= {"default", "home"}
    assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_CAMERA, "scene_camera") >= 0
    free = [
        m.body(m.jnt_bodyid[j]).name for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE
    ]
    assert free[0] == "cube" and "tag_block" in free  # the cube's qpos comes first; tagged objects after
    assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "tray") >= 0
    assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "grasp_site") >= 0


def test_robot_holds_the_default_keyframe(cell):
    """With ctrl from the keyframe the servos hold the arm still and the free objects rest on the table."""
    import mujoco

    m, d = cell.m, cell.d
    free = [
        m.body(m.jnt_bodyid[j]).name for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE
    ]
    assert {"cube", "tag_block", "flask_1", "flask_2"} <= set(free), free
    q0 = cell.arm_q()
    start = {name: cell.body_pos(name) for name in free}
    cell.step(2.0)
    assert np.abs(cell.arm_q() - q0).max() < 1e-3
    for name, position in start.items():
        assert np.linalg.norm(cell.body_pos(name) - position) < 1e-3, name
    objects = {m.body(name).id for name in free}
    touching = {
        m.body(m.geom_bodyid[g]).name
        for c in d.contact[: d.ncon]
        for g in (c.geom1, c.geom2)
        if m.geom_bodyid[g] != 0 and m.geom_bodyid[g] not in objects
    }
    assert not touching, f"only objects rest on the table; the robot touches nothing: {touching}"


def test_waypoints_file_has_moveit_pro_format_and_names():
    entries = yaml.safe_load((LAB_SIM / "waypoints" / "lab_sim_waypoints.yaml").read_text())
    names = {e["name"] for e in entries}
    assert {
        "3 Waypoint Mid Point",
        "3 Waypoint Pick Pose",
        "3 Waypoint Place Pose",
        "Look at Table",
        "Home",
    } <= names
    for e in entries:
        assert e["joint_group_names"] == ["gripper", "linear_actuator", "manipulator"]
        assert e["joint_state"]["name"] == [GRIPPER, *ARM]
        assert len(e["joint_state"]["position"]) == 8
        assert set(e) == {
            "description",
            "favorite",
            "joint_group_names",
            "joint_state",
            "multi_dof_joint_state",
            "name",
        }
