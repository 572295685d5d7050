"""The gripper controller's logic on a fake gripper (no MuJoCo): reached, stalled, effort cap, cancel."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from kinema.drivers.mujoco.execution import Execution
from kinema.drivers.mujoco.gripper_controller import GripperController, GripperSettings
from kinema.drivers.mujoco.model_index import JointInfo

DT = 0.002
SPEED = 2.0  # knuckle units per second


class Gripper:
    """Stands in for MjModel/MjData: the knuckle slides toward ctrl at SPEED until it meets ``blocked_at``."""

    def __init__(self, blocked_at: float | None = None) -> None:
        self.model = SimpleNamespace(
            actuator_ctrlrange=np.array([[0.0, 0.7929]]),
            actuator_ctrllimited=np.array([1]),
            actuator_forcerange=np.array([[-3.0, 3.0]]),
            actuator_forcelimited=np.array([1]),
        )
        self.time = 0.0
        self.qpos = np.zeros(1)
        self.qvel = np.zeros(1)
        self.ctrl = np.zeros(1)
        self.actuator_force = np.zeros(1)
        self.blocked_at = blocked_at

    def step(self, controller: GripperController) -> None:
        controller.update(self)
        target = float(self.ctrl[0])
        if self.blocked_at is not None:
            target = min(target, self.blocked_at)
        move = float(np.clip(target - self.qpos[0], -SPEED * DT, SPEED * DT))
        self.qpos[0] += move
        self.qvel[0] = move / DT
        limit = float(self.model.actuator_forcerange[0, 1])
        self.actuator_force[0] = float(np.clip(20.0 * (self.ctrl[0] - self.qpos[0]), -limit, limit))
        self.time += DT

    def run(self, controller: GripperController, execution: Execution, limit: float = 5.0) -> None:
        while not execution.done.is_set() and self.time < limit:
            self.step(controller)


def make(gripper: Gripper) -> GripperController:
    joint = JointInfo("knuckle", 0, 0, (0.0, 0.7929), 0)
    controller = GripperController("gripper", joint, gripper.model, GripperSettings())
    controller.activate(gripper)
    return controller


def command(
    controller: GripperController, gripper: Gripper, position: float, effort: float = 0.0
) -> Execution:
    execution = Execution("goal")
    controller.start(execution, position, effort, gripper)
    return execution


def test_closing_on_nothing_reaches_the_goal() -> None:
    gripper = Gripper()
    controller = make(gripper)
    execution = command(controller, gripper, 0.7929)
    gripper.run(controller, execution)
    assert execution.outcome is not None and execution.outcome.status == "succeeded"
    assert execution.outcome.result["reached_goal"] and not execution.outcome.result["stalled"]
    assert execution.outcome.result["position"] == pytest.approx(0.7929, abs=0.01)


def test_closing_on_an_object_stalls_and_keeps_squeezing() -> None:
    gripper = Gripper(blocked_at=0.33)
    controller = make(gripper)
    execution = command(controller, gripper, 0.7929)
    gripper.run(controller, execution)
    assert execution.outcome is not None and execution.outcome.status == "succeeded"
    assert execution.outcome.result["stalled"] and not execution.outcome.result["reached_goal"]
    assert execution.outcome.result["position"] == pytest.approx(0.33)
    # It stalled once still for the stall timeout, not before.
    assert gripper.time == pytest.approx(0.33 / SPEED + GripperSettings().stall_timeout, abs=0.01)
    assert gripper.ctrl[0] == pytest.approx(0.7929)


def test_max_effort_caps_the_force_for_that_goal_only() -> None:
    gripper = Gripper(blocked_at=0.33)
    controller = make(gripper)
    execution = command(controller, gripper, 0.7929, effort=1.0)
    gripper.run(controller, execution)
    assert execution.outcome is not None
    assert execution.outcome.result["effort"] == pytest.approx(1.0)
    command(controller, gripper, 0.0)
    assert gripper.model.actuator_forcerange[0].tolist() == [-3.0, 3.0]


def test_targets_outside_the_range_are_clamped() -> None:
    gripper = Gripper()
    controller = make(gripper)
    command(controller, gripper, 1.5)
    assert gripper.ctrl[0] == pytest.approx(0.7929)


def test_cancel_holds_where_the_gripper_is() -> None:
    gripper = Gripper()
    controller = make(gripper)
    execution = command(controller, gripper, 0.7929)
    for _ in range(50):
        gripper.step(controller)
    controller.cancel(execution, gripper)
    assert execution.outcome is not None and execution.outcome.status == "canceled"
    assert gripper.ctrl[0] == pytest.approx(gripper.qpos[0])


def test_an_inactive_gripper_aborts_goals() -> None:
    gripper = Gripper()
    controller = make(gripper)
    controller.deactivate(gripper)
    execution = command(controller, gripper, 0.7929)
    assert execution.outcome is not None and execution.outcome.status == "aborted"
    assert gripper.ctrl[0] == 0.0
