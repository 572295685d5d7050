"""Fixtures for the lab_sim model tests: the MuJoCo scene and a minimal trajectory tracker."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from kinema.motion import JointTrajectory, RobotDescription

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


@pytest.fixture(scope="session")
def description() -> RobotDescription:
    return RobotDescription.lab_sim()


@dataclass
class Cell:
    """The MuJoCo scene at its ``default`` keyframe, driven by setting actuator targets directly."""

    m: object
    d: object

    def qpos(self, joint: str) -> float:
        return float(self.d.joint(joint).qpos[0])

    def arm_q(self) -> np.ndarray:
        return np.array([self.qpos(j) for j in ARM])

    def body_pos(self, body: str) -> np.ndarray:
        return self.d.body(body).xpos.copy()

    def step(self, seconds: float) -> None:
        import mujoco

        for _ in range(round(seconds / self.m.opt.timestep)):
            mujoco.mj_step(self.m, self.d)

    def track(self, traj: JointTrajectory, settle: float = 0.3) -> None:
        """Follow a timed trajectory with the position servos (velocity feed-forward: ctrl = q + kv/kp qd)."""
        import mujoco

        ids = [self.m.actuator(j).id for j in traj.joint_names]
        kp = self.m.actuator_gainprm[ids, 0]
        kv = -self.m.actuator_biasprm[ids, 2]
        dt = self.m.opt.timestep
        for k in range(int(np.ceil(traj.duration / dt)) + 1):
            q, qd, _ = traj.sample(k * dt)
            self.d.ctrl[ids] = q + kv / kp * qd
            mujoco.mj_step(self.m, self.d)
        self.step(settle)

    def grip(self, position: float, seconds: float = 0.6) -> None:
        self.d.ctrl[self.m.actuator(GRIPPER).id] = position
        self.step(seconds)


@pytest.fixture
def cell(description: RobotDescription) -> Cell:
    import mujoco

    m = mujoco.MjModel.from_xml_path(str(description.mjcf))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("default").id)
    mujoco.mj_forward(m, d)
    return Cell(m, d)
