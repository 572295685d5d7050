"""Robots nobody here wrote: the Franka Panda and the UR5 of example-robot-data, from their URDF to motion.

Each is made into a config package with the generator behind ``kinema new config --from-urdf`` in a
temporary workspace, checked by ``kinema build``, and run as a cell (router, MuJoCo driver, agent and an
SDK client in this process): moving between two waypoints, a Cartesian move of the tool, and (Panda) the
gripper. Positions are the simulator's own.
"""

from __future__ import annotations

import math
import subprocess
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from kinema.config.robot_files import PackageIndex

pytestmark = pytest.mark.slow

_SHARE = PackageIndex(packages={}).find("example-robot-data")
if _SHARE is None:
    pytest.skip(
        "example-robot-data is not installed (pip install example-robot-data, in the test extra)",
        allow_module_level=True,
    )
ROBOTS = Path(_SHARE) / "robots"
PANDA = (ROBOTS / "panda_description/urdf/panda.urdf", ROBOTS / "panda_description/srdf/panda.srdf")
UR5 = (ROBOTS / "ur_description/urdf/ur5_robot.urdf", ROBOTS / "ur_description/srdf/ur5.srdf")

CARTESIAN = """<root BTCPP_format="4" main_tree_to_execute="Cartesian">
  <BehaviorTree ID="Cartesian">
    <Sequence>
      <Action ID="CreatePoseStamped" reference_frame="{tool}" position_xyz="{offset}"
              orientation_xyzw="0;0;0;1" pose_stamped="{pose}"/>
      <Action ID="ResetPoseStampedVector" vector="{path}"/>
      <Action ID="PushBackVector" input_vector="{path}" element="{pose}" output_vector="{path}"/>
      <Action ID="PlanCartesianPath" path="{path}" joint_trajectory_msg="{trajectory}"/>
      <Action ID="ExecuteTrajectory" joint_trajectory_msg="{trajectory}"/>
    </Sequence>
  </BehaviorTree>
</root>"""


@dataclass
class RobotCell:
    name: str
    root: Path
    plan: Any
    driver: Any
    client: Any

    def joints(self, names: list[str]) -> dict[str, float]:
        index = self.driver.index

        def read() -> dict[str, float]:
            return {n: float(self.driver.data.qpos[index.joint(n).qpos_address]) for n in names}

        return dict(self.driver.simulation.call(read))

    def tool_position(self) -> np.ndarray:
        import mujoco

        model, data = self.driver.model, self.driver.data
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, self.plan.tool_frame)
        assert body >= 0, f"the scene has no body {self.plan.tool_frame!r}"
        return np.array(self.driver.simulation.call(lambda: data.xpos[body].copy()))


def _add_waypoint(root: Path, name: str, values: dict[str, float], group: str) -> None:
    path = root / "waypoints" / "waypoints.yaml"
    joint_names = list(values)
    path.write_text(
        path.read_text()
        + f"- name: {name!r}\n  joint_group_names: [{group}]\n  joint_state:\n"
        + "    header: {frame_id: ''}\n"
        + f"    name: [{', '.join(joint_names)}]\n"
        + f"    position: [{', '.join(repr(values[j]) for j in joint_names)}]\n"
        + "    velocity: []\n    effort: []\n"
    )


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("own_robot_ws")
    (root / "src").mkdir()
    return root


@pytest.fixture(scope="module")
def start_cell(workspace: Path) -> Iterator[Callable[..., RobotCell]]:
    from kinema.config import Workspace
    from kinema.drivers.mujoco import MujocoDriver, MujocoDriverSettings
    from kinema.runtime.agent_process import AgentOptions, build_agent
    from kinema.scaffold.robot_package import new_robot_package
    from kinema.sdk import ObjectiveClient
    from kinema.transport import free_endpoint, host_router, open_session

    cleanup: list[Callable[[], Any]] = []

    def start(name: str, urdf: Path, srdf: Path, reach: dict[str, float]) -> RobotCell:
        package, plan = new_robot_package(name, urdf, srdf=srdf, workspace=Workspace.discover(workspace))
        reach_values = dict(plan.home)
        reach_values.update(reach)
        _add_waypoint(package, "Reach", reach_values, plan.planning_group)
        built = subprocess.run(
            [sys.executable, "-m", "kinema.cli.main", "build", "-w", str(workspace), "-c", name],
            capture_output=True,
            text=True,
            timeout=240,
        )
        assert built.returncode == 0, built.stdout + built.stderr
        endpoint = free_endpoint()
        router = host_router(endpoint)
        cleanup.append(router.close)
        driver_session = open_session(endpoint)
        cleanup.append(driver_session.close)
        settings = MujocoDriverSettings.from_config(name, Workspace.discover(workspace), sim_speed=math.inf)
        driver = MujocoDriver(driver_session, settings)
        driver.start()
        cleanup.append(driver.stop)
        agent_session = open_session(endpoint)
        cleanup.append(agent_session.close)
        agent = build_agent(
            AgentOptions(config=name, workspace=workspace, clock="sim", hot_reload=False), agent_session
        )
        agent.start()
        cleanup.append(agent.close)
        client_session = open_session(endpoint)
        cleanup.append(client_session.close)
        client = ObjectiveClient(session=client_session)
        cleanup.append(client.close)
        client.wait_for_runtime()
        return RobotCell(name, package, plan, driver, client)

    yield start
    for step in reversed(cleanup):
        step()


def _moves_between_waypoints(cell: RobotCell) -> None:
    joints = cell.plan.group_joints
    reach = cell.client.execute("Move to Waypoint", {"waypoint_name": "Reach"}, timeout=180)
    assert reach.succeeded, reach
    at_reach = cell.joints(joints)
    home = cell.client.execute("Move to Waypoint", {"waypoint_name": "Home"}, timeout=180)
    assert home.succeeded, home
    at_home = cell.joints(joints)
    for joint in joints:
        assert abs(at_home[joint] - cell.plan.home[joint]) < 0.02, (joint, at_home, cell.plan.home)
    assert max(abs(at_reach[j] - at_home[j]) for j in joints) > 0.3, (at_reach, at_home)


def _cartesian_move(cell: RobotCell, offset: str, expected: float) -> None:
    before = cell.tool_position()
    xml = CARTESIAN.replace("{tool}", cell.plan.tool_frame).replace("{offset}", offset)
    result = cell.client.do_xml(xml, timeout=180)
    assert result.succeeded, result
    moved = float(np.linalg.norm(cell.tool_position() - before))
    assert moved == pytest.approx(expected, abs=0.01), f"the tool moved {moved:.3f} m"


def _finger_settles(cell: RobotCell, reached: Callable[[float], bool], seconds: float = 10.0) -> bool:
    """Whether the Panda's finger position meets ``reached`` within ``seconds`` (wall)."""
    import time

    deadline = time.monotonic() + seconds
    while not reached(cell.joints(["panda_finger_joint1"])["panda_finger_joint1"]):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.02)
    return True


def test_the_panda_with_its_hand_from_its_urdf(start_cell: Callable[..., RobotCell]) -> None:
    cell = start_cell("panda_cell", *PANDA, {"panda_joint1": 0.6, "panda_joint4": -1.9})
    assert cell.plan.planning_group == "arm"  # the SRDF's arm, not emptied by arm_and_hand
    assert cell.plan.gripper_joint == "panda_finger_joint1"
    _moves_between_waypoints(cell)
    _cartesian_move(cell, "0;0;0.05", 0.05)
    closed = cell.client.execute("Close Gripper", timeout=60)
    assert closed.succeeded, closed
    # The gripper controller reports success within its goal tolerance (1 cm); the empty hand goes on to 0.
    assert _finger_settles(cell, lambda q: q < 0.005), "the empty hand did not close"
    # The generated Close Gripper has the grasp check a pick sets: this hand holds nothing.
    empty = cell.client.execute("Close Gripper", {"require_grasp": True}, timeout=60)
    assert empty.failed and "the gripper closed on nothing" in empty.error_message, empty
    opened = cell.client.execute("Open Gripper", timeout=60)
    assert opened.succeeded, opened
    assert _finger_settles(cell, lambda q: q > 0.035), "the hand did not open"


def test_the_ur5_from_its_urdf(start_cell: Callable[..., RobotCell]) -> None:
    cell = start_cell(
        "ur5_cell", *UR5, {"shoulder_pan_joint": 0.8, "shoulder_lift_joint": -1.0, "elbow_joint": 0.6}
    )
    assert cell.plan.planning_group == "manipulator"  # its SRDF has no groups: the longest chain
    assert cell.plan.gripper_joint is None
    _moves_between_waypoints(cell)
    _cartesian_move(cell, "0;0;0.05", 0.05)
