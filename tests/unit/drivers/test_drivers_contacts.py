"""Naming what the robot touches, on a small MuJoCo model: a two-link arm, a table and a loose block."""

from __future__ import annotations

import mujoco

from kinema.drivers.mujoco.contacts import contact_reporter, robot_bodies

SCENE = """
<mujoco>
  <worldbody>
    <geom name="table" type="box" size="1 1 0.05" pos="0 0 -0.05"/>
    <body name="base" pos="0 0 1">
      <joint name="lift" type="slide" axis="0 0 1"/>
      <geom type="box" size="0.05 0.05 0.05"/>
      <body name="upper_arm" pos="0 0 -0.42">
        <joint name="shoulder" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.01"/>
        <body name="finger" pos="0 0 -0.5">
          <geom name="finger" type="box" size="0.02 0.02 0.02"/>
        </body>
      </body>
    </body>
    <body name="block" pos="{x} 0 0.03">
      <freejoint/>
      <geom type="box" size="0.03 0.03 0.03"/>
    </body>
  </worldbody>
</mujoco>
"""
JOINTS = ["lift", "shoulder"]


def _state(block_x: float, lift: float) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """The arm hangs straight down, its finger's bottom 0.06 m above the table (the block's top)
    less ``-lift``; the block stands ``block_x`` to the side of it."""
    model = mujoco.MjModel.from_xml_string(SCENE.format(x=block_x))
    data = mujoco.MjData(model)
    data.qpos[0] = lift
    mujoco.mj_forward(model, data)
    return model, data


def test_the_robot_is_what_its_joints_move() -> None:
    model, _ = _state(0.5, 0.0)
    robot = robot_bodies(model, JOINTS)
    assert [model.body(i).name for i in range(model.nbody) if robot[i]] == ["base", "upper_arm", "finger"]


def test_contacts_name_the_touched_thing_and_the_robot_parts() -> None:
    model, data = _state(0.5, 0.0)
    assert contact_reporter(model, JOINTS)(data) == []  # the block rests on the table: not the robot
    model, data = _state(0.0, -0.01)  # the finger pressed into the block
    assert contact_reporter(model, JOINTS)(data) == ["block (finger)"]
    # The table is a geom of the world: it is named by the geom's name.
    model, data = _state(0.5, -0.07)
    assert contact_reporter(model, JOINTS)(data) == ["table (finger)"]
