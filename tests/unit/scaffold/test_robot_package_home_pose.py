"""The generated Home of a robot without an SRDF home state: the rest pose when a user can work from it,
else a bent pose (see :mod:`kinema.scaffold.home_pose`).

A new user's UR10 (example-robot-data, no SRDF) started with every joint at 0: lying stretched along the
table, elbow and wrist singular, and every Cartesian move from Home failed ("no IK solution ... out of
reach"; moving up collided the forearm with the table).
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from kinema.config.robot_files import PackageIndex
from kinema.motion.collision import CollisionChecker
from kinema.motion.inverse_kinematics import IkOptions, ik
from kinema.motion.kinematics import fk
from kinema.motion.planning_scene import PlanningScene
from kinema.motion.robot_model import RobotModel
from kinema.scaffold.home_pose import choose_home
from kinema.scaffold.robot_package import RobotPlan, _config_yaml, plan_robot


@pytest.fixture(scope="module")
def robots() -> Path:
    share = PackageIndex(environ={}).find("example-robot-data")
    if share is None:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data, in the test extra)")
    return share / "robots"


def plan(urdf: Path, srdf: Path | None = None) -> RobotPlan:
    return plan_robot("cell", urdf, srdf=srdf, xacro_args=None, index=PackageIndex(environ={}))


def loaded(plan: RobotPlan) -> Iterator[RobotModel]:
    """The plan's robot as the planner loads it: its URDF and the generated SRDF (disabled pairs)."""
    with tempfile.TemporaryDirectory() as folder:
        urdf = plan.robot.write_urdf(Path(folder) / "robot.urdf")
        srdf = Path(folder) / "robot.srdf"
        srdf.write_text(plan.srdf_text)
        yield RobotModel.from_urdf(urdf, srdf)


def table_checker(model: RobotModel) -> CollisionChecker:
    """Self-collision and the table top at z = 0 (the links fixed to the base stand on it)."""
    scene = PlanningScene()
    pose = np.eye(4)
    pose[2, 3] = -0.05
    scene.add_box("table", (3.0, 3.0, 0.05), pose)
    checker = CollisionChecker(model, scene)
    # The shoulder turns about the vertical on its base: where it touches the table it was built to.
    checker.allowed_collisions = [("shoulder_link", "table")]
    return checker


@pytest.mark.parametrize("arm", ["ur5_robot", "ur10_robot"])
def test_a_ur_without_srdf_gets_a_home_it_can_move_from(robots: Path, arm: str) -> None:
    made = plan(robots / "ur_description" / "urdf" / f"{arm}.urdf")
    assert any(value != 0.0 for value in made.home.values()), made.home
    assert any(note.startswith("Home is not every joint at 0, which is near-singular") for note in made.notes)
    # A height under the table top is said as such ("-0.01 m above the table top", a new user read).
    assert not any(" -0." in note for note in made.notes), made.notes
    for model in loaded(made):
        checker = table_checker(model)
        home = model.configuration({n: v for n, v in made.home.items() if n in model.joint_names})
        rest = model.neutral()
        assert checker.colliding_pairs(home) == []
        assert checker.colliding_pairs(rest) != []  # the stretched arm lies on the table
        # A measure of its own (position rows only), not the chooser's: Home is further from singular.
        columns = list(model.group(made.planning_group).indices)

        def dexterity(q: np.ndarray, model: RobotModel = model, columns: list[int] = columns) -> float:
            import pinocchio as pin

            pm, data = model.pin_model, model.new_data()
            pin.computeJointJacobians(pm, data, model.pin_configuration(q))
            pin.updateFramePlacements(pm, data)
            frame = model.frame_id(made.tool_frame)
            jacobian = pin.getFrameJacobian(pm, data, frame, pin.LOCAL_WORLD_ALIGNED)[:, columns]
            return float(np.prod(np.linalg.svd(jacobian, compute_uv=False)))

        assert dexterity(rest) < 1e-6 < dexterity(home)
        start = fk(model, home, made.tool_frame)
        assert start[2, 3] > 0.2  # well above the table top
        for axis in range(3):
            for step in (0.05, -0.05):
                goal = start.copy()
                goal[axis, 3] += step
                solution = ik(
                    model,
                    goal,
                    home,
                    made.planning_group,
                    made.tool_frame,
                    options=IkOptions(attempts=1),
                    accept=lambda q, checker=checker: not checker.in_collision(q),
                )
                reached = fk(model, solution, made.tool_frame)
                assert np.allclose(reached[:3, 3], goal[:3, 3], atol=1e-3), (axis, step)


def test_the_chosen_home_and_why_are_in_config_yaml(robots: Path) -> None:
    made = plan(robots / "ur_description" / "urdf" / "ur10_robot.urdf")
    text = _config_yaml(made, "cell_scene.xml", "ur10_robot.urdf")
    lines = text.splitlines()
    keyframe = next(n for n, line in enumerate(lines) if "mujoco_keyframe" in line)
    start = next(n for n in range(keyframe, 0, -1) if "The simulation starts in" in lines[n])
    comment = " ".join(line.strip().removeprefix("# ") for line in lines[start + 1 : keyframe])
    assert "Home is not every joint at 0, which is near-singular" in comment
    assert "give an SRDF with a group state 'home' (--srdf)" in comment
    assert made.home_note is not None and made.home_note in made.notes


def test_the_choice_is_deterministic(robots: Path) -> None:
    urdf = robots / "ur_description" / "urdf" / "ur5_robot.urdf"
    assert plan(urdf).home == plan(urdf).home


def test_an_srdf_home_state_is_home_as_given(robots: Path) -> None:
    folder = robots / "panda_description"
    made = plan(folder / "urdf" / "panda.urdf", folder / "srdf" / "panda.srdf")
    default = made.semantic.group_states[("arm_and_hand", "default")]
    arm = {n: made.home[n] for n in made.group_joints}
    assert arm == pytest.approx({n: float(default[n]) for n in made.group_joints})
    assert made.home["panda_joint4"] == pytest.approx(-2.356, abs=1e-3)
    assert made.home_note is None


def test_a_rest_pose_a_user_can_work_from_stays_home(robots: Path) -> None:
    """The SO-101 at 0 stands bent, its tool 23 cm above the table: nothing to improve."""
    made = plan(robots / "so_arm_description" / "urdf" / "so101.urdf")
    assert {n: v for n, v in made.home.items() if n != made.gripper_joint} == dict.fromkeys(
        made.group_joints, 0.0
    )
    assert made.home_note is None
    assert not any("Home is" in note for note in made.notes), made.notes
    for model in loaded(made):
        choice = choose_home(model, made.planning_group, made.tool_frame, made.home)
        assert not choice.changed and choice.problems == []
        assert choice.manipulability == choice.rest_manipulability > 0.01


def test_a_rest_pose_no_bend_improves_stays_and_is_said(tmp_path: Path) -> None:
    """A two-joint arm turning about the vertical, 2 cm above the table: low at every angle."""
    limit = '<limit lower="-2" upper="2" effort="10" velocity="1"/>'
    urdf = tmp_path / "sweeper.urdf"
    urdf.write_text(
        f"""<?xml version="1.0"?>
<robot name="sweeper">
  <link name="base"/>
  <link name="upper"/>
  <link name="lower"/>
  <joint name="turn" type="revolute">
    <parent link="base"/><child link="upper"/><origin xyz="0 0 0.02"/><axis xyz="0 0 1"/>{limit}
  </joint>
  <joint name="sweep" type="revolute">
    <parent link="upper"/><child link="lower"/><origin xyz="0.2 0 0"/><axis xyz="0 0 1"/>{limit}
  </joint>
</robot>
"""
    )
    made = plan(urdf)
    assert made.home == {"turn": 0.0, "sweep": 0.0}
    assert made.home_note is not None
    assert made.home_note.startswith("Home is every joint at 0, though it is"), made.home_note
    assert "no bent pose was better" in made.home_note
