"""URDF objects in the planning scene: their collision shapes, attaching them to a link, and what the planner
then checks (kinema.motion.urdf_objects, PlanningScene.attach/detach, CollisionChecker)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from kinema.errors import MotionError
from kinema.motion import CollisionChecker, PlanningScene, RobotModel, fk
from kinema.motion.planning_scene_messages import planning_scene_message
from kinema.motion.urdf_objects import load_urdf_object, urdf_object_from_text

ARM = [
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
]
HOME = [0.0, 0.0, -2.0, 2.0, -1.5708, -1.5708, 0.0]
# grasp_link 0.30 m above the table top, pointing down (HOME is beside the table)
OVER_TABLE = [-0.1333, 0.0, -1.25758, 1.37827, -1.69149, -1.5708, 0.0]

# A rod along the root link's z from 2 cm to 42 cm, and a 1 cm ball at its end on a child link.
ROD = """<?xml version="1.0"?>
<robot name="rod_tool">
  <link name="tool_base">
    <collision>
      <origin xyz="0 0 0.22"/>
      <geometry><box size="0.04 0.04 0.40"/></geometry>
    </collision>
  </link>
  <link name="tip"><collision><geometry><sphere radius="0.01"/></geometry></collision></link>
  <joint name="tip_joint" type="fixed">
    <parent link="tool_base"/><child link="tip"/><origin xyz="0 0 0.43"/>
  </joint>
</robot>
"""


def _q(model: RobotModel, arm: list[float]) -> np.ndarray:
    q = np.zeros(len(model.joint_names))
    q[[model.joint_names.index(n) for n in ARM]] = arm
    return q


def test_links_are_placed_through_their_joints_and_a_movable_joint_is_held_at_zero(tmp_path: Path) -> None:
    import trimesh

    trimesh.creation.box(extents=(0.2, 0.1, 0.05)).apply_translation((0.1, 0, 0)).export(tmp_path / "jaw.stl")
    (tmp_path / "gripper.urdf").write_text(
        """<robot name="gripper">
          <link name="base"><collision><origin xyz="0 0 0.05" rpy="0 1.5707963 0"/>
            <geometry><cylinder radius="0.04" length="0.1"/></geometry></collision></link>
          <link name="jaw"><collision><geometry><mesh filename="jaw.stl" scale="0.5 1 1"/></geometry>
            </collision></link>
          <joint name="slide" type="prismatic"><parent link="base"/><child link="jaw"/>
            <origin xyz="0 0 0.1" rpy="0 0 1.5707963"/><axis xyz="1 0 0"/>
            <limit lower="0" upper="0.04" effort="1" velocity="1"/></joint>
          <ros2_control name="g" type="system"/>
        </robot>"""
    )
    tool = load_urdf_object(tmp_path / "gripper.urdf")
    assert (tool.name, tool.root_link, tool.held_joints, tool.ros2_control) == (
        "gripper",
        "base",
        ("slide",),
        True,
    )
    cylinder, jaw = tool.shapes
    assert cylinder.shape == "cylinder" and cylinder.size == pytest.approx((0.04, 0.05))
    np.testing.assert_allclose(cylinder.world_T_object[:3, 2], [1, 0, 0], atol=1e-6)  # turned about y
    # the mesh: its bounding box (x from 0 to 0.2, scaled by 0.5), turned 90 degrees about z by the joint
    assert jaw.shape == "box" and jaw.size == pytest.approx((0.05, 0.05, 0.025))
    np.testing.assert_allclose(jaw.world_T_object[:3, 3], [0.0, 0.05, 0.1], atol=1e-6)


def _one_link(geometry: str) -> str:
    collision = f"<collision><geometry>{geometry}</geometry></collision>"
    return f"<robot name='r'><link name='a'>{collision}</link></robot>"


@pytest.mark.parametrize(
    ("urdf", "message"),
    [
        ("<robot name='r'><link name='a'/></robot>", "no <collision> geometry"),
        ("<robot name='r'><link name='a'/><link name='b'/></robot>", "one root link"),
        (_one_link("<cone/>"), "<cone>"),
        (_one_link("<box size='1 2'/>"), "3 finite"),
        (_one_link("<mesh filename='gone.stl'/>"), "mesh not found"),
        ("<robt/>", "not a URDF"),
    ],
)
def test_a_urdf_the_planner_cannot_check_is_refused_with_the_reason(
    urdf: str, message: str, tmp_path: Path
) -> None:
    with pytest.raises(MotionError, match=re.escape(message)):
        urdf_object_from_text(urdf, base_dir=tmp_path)


def test_an_attached_urdf_moves_with_its_link_and_the_planner_checks_it(
    model: RobotModel, lab_scene: PlanningScene
) -> None:
    scene = PlanningScene(dict(lab_scene.objects))
    checker = CollisionChecker(model, scene)
    home, over = _q(model, HOME), _q(model, OVER_TABLE)
    world_T_grasp = fk(model, home, "grasp_link")
    rod = urdf_object_from_text(ROD, base_dir=".")
    scene.add_world_object("rod", rod.placed(world_T_grasp), pose=world_T_grasp, urdf=True)
    # in the world the rod stays beside the table while the arm moves over it: no collision
    assert not checker.in_collision(home) and not checker.in_collision(over)
    scene.attach("rod", "grasp_link", world_T_grasp)
    assert scene.world.get("rod") is None and set(scene.attached) == {"rod"}
    assert not checker.in_collision(home)
    # carried over the table, the 42 cm rod reaches 12 cm into it
    assert set(checker.colliding_pairs(over)) == {("rod/0", "table"), ("rod/1", "table")}
    scene.detach("rod", fk(model, over, "grasp_link"))
    assert scene.urdf_ids == {"rod"} and not scene.attached
    np.testing.assert_allclose(scene.world_poses["rod"], fk(model, over, "grasp_link"), atol=1e-9)
    assert not checker.in_collision(home)  # left behind in the table, where the arm no longer is


def test_an_attached_object_may_touch_its_link_and_touch_links_only(
    model: RobotModel, lab_scene: PlanningScene
) -> None:
    scene = PlanningScene(dict(lab_scene.objects))
    checker = CollisionChecker(model, scene)
    home = _q(model, HOME)
    world_T_wrist = fk(model, home, "wrist_3_link")
    # a ball around the gripper's base: it overlaps the gripper links
    ball = urdf_object_from_text(
        "<robot name='b'><link name='b'><collision><origin xyz='0 0 0.05'/><geometry><sphere radius='0.06'/>"
        "</geometry></collision></link></robot>",
        base_dir=".",
    )
    scene.add_world_object("ball", ball.placed(world_T_wrist), pose=world_T_wrist, urdf=True)
    scene.attach("ball", "wrist_3_link", world_T_wrist)
    touching = {link for pair in checker.colliding_pairs(home) for link in pair if link != "ball"}
    assert touching and "wrist_3_link" not in touching
    scene.detach("ball", world_T_wrist)
    scene.attach("ball", "wrist_3_link", world_T_wrist, touching)
    assert not checker.in_collision(home)


def test_attached_objects_cannot_be_moved_replaced_or_removed_and_reset_clears_them(
    model: RobotModel,
) -> None:
    scene = PlanningScene()
    rod = urdf_object_from_text(ROD, base_dir=".")
    scene.add_world_object("rod", rod.placed(np.eye(4)), urdf=True)
    scene.attach("rod", "tool0", np.eye(4))
    for change in (
        lambda: scene.remove_world_object("rod"),
        lambda: scene.move_world_object("rod", np.eye(4)),
        lambda: scene.add_world_object("rod", rod.placed(np.eye(4))),
        lambda: scene.attach("rod", "tool0", np.eye(4)),
    ):
        with pytest.raises(MotionError, match="attached"):
            change()
    with pytest.raises(
        MotionError, match="no collision object 'rd' is attached to the robot; did you mean 'rod'"
    ):
        scene.detach("rd", np.eye(4))
    assert scene.reset_world() == 1 and not scene.attached and not scene.urdf_ids


def test_the_scene_message_lists_attached_objects_in_their_links_frame(model: RobotModel) -> None:
    scene = PlanningScene()
    rod = urdf_object_from_text(ROD, base_dir=".")
    world_T_link = np.eye(4)
    world_T_link[:3, 3] = [1.0, 2.0, 3.0]
    scene.add_world_object("rod", rod.placed(world_T_link), pose=world_T_link, urdf=True)
    scene.attach("rod", "tool0", world_T_link, ["wrist_3_link"])
    message = planning_scene_message(scene)
    assert list(message.world.collision_objects) == []
    (item,) = message.robot_state.attached_collision_objects
    assert item.link_name == "tool0" and sorted(item.touch_links) == ["tool0", "wrist_3_link"]
    assert item.object.id == "rod" and item.object.header.frame_id == "tool0"
    assert [p.position.z for p in item.object.primitive_poses] == pytest.approx([0.22, 0.43])


def test_the_robots_bounds_include_what_it_carries(model: RobotModel) -> None:
    scene = PlanningScene()
    checker = CollisionChecker(model, scene)
    home = _q(model, HOME)
    bare = checker.robot_bounds(home)
    world_T_grasp = fk(model, home, "grasp_link")
    rod = urdf_object_from_text(ROD, base_dir=".")
    scene.add_world_object("rod", rod.placed(world_T_grasp), pose=world_T_grasp, urdf=True)
    assert len(checker.robot_bounds(home)) == len(bare)  # in the world it is not the robot's
    scene.attach("rod", "grasp_link", world_T_grasp)
    carried = checker.robot_bounds(home)
    assert len(carried) == len(bare) + 2
    tip = (world_T_grasp @ [0, 0, 0.43, 1])[:3]
    assert any(np.all(low <= tip) and np.all(tip <= high) for low, high in carried[len(bare) :])
