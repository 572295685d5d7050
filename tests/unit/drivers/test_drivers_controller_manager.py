"""Switching controllers the way ros2_control's controller manager does."""

from __future__ import annotations

from typing import Any

import pytest

from kinema.drivers.mujoco.controller_manager import (
    BEST_EFFORT,
    STRICT,
    ControllerManager,
    JointStateBroadcaster,
)


class FakeController:
    type_name = "fake/Controller"

    def __init__(self, name: str, joints: list[str]) -> None:
        self.name = name
        self.joints = joints
        self.active = False
        self.calls: list[str] = []

    @property
    def command_interfaces(self) -> list[str]:
        return [f"{j}/position" for j in self.joints]

    @property
    def state_interfaces(self) -> list[str]:
        return [f"{j}/position" for j in self.joints]

    def activate(self, data: Any) -> None:
        self.active = True
        self.calls.append("activate")

    def deactivate(self, data: Any) -> None:
        self.active = False
        self.calls.append("deactivate")


@pytest.fixture
def manager() -> ControllerManager:
    arm = FakeController("arm_controller", ["a", "b"])
    admittance = FakeController("admittance_controller", ["a", "b"])
    gripper = FakeController("gripper_controller", ["g"])
    broadcaster = JointStateBroadcaster("joint_state_broadcaster", ["a", "b", "g"])
    for controller in (arm, gripper, broadcaster):
        controller.activate(None)
    return ControllerManager([broadcaster, arm, admittance, gripper], update_rate=500)


def states(manager: ControllerManager) -> dict[str, str]:
    return {s["name"]: s["state"] for s in manager.list_states()}


def test_list_reports_state_type_and_claimed_interfaces(manager: ControllerManager) -> None:
    listed = {s["name"]: s for s in manager.list_states()}
    assert list(listed) == [
        "joint_state_broadcaster",
        "arm_controller",
        "admittance_controller",
        "gripper_controller",
    ]
    assert listed["arm_controller"]["claimed_interfaces"] == ["a/position", "b/position"]
    assert listed["admittance_controller"]["claimed_interfaces"] == []
    assert listed["admittance_controller"]["required_command_interfaces"] == ["a/position", "b/position"]
    assert listed["joint_state_broadcaster"]["type"] == "joint_state_broadcaster/JointStateBroadcaster"
    assert listed["arm_controller"]["update_rate"] == 500


def test_switching_between_controllers_that_share_joints(manager: ControllerManager) -> None:
    ok, message = manager.switch(["admittance_controller"], ["arm_controller"], STRICT, None)
    assert ok, message
    assert states(manager)["arm_controller"] == "inactive"
    assert states(manager)["admittance_controller"] == "active"


def test_a_conflicting_activation_is_refused_when_strict(manager: ControllerManager) -> None:
    ok, message = manager.switch(["admittance_controller"], [], STRICT, None)
    assert not ok
    assert "a/position" in message and "arm_controller" in message
    assert states(manager)["admittance_controller"] == "inactive"


def test_best_effort_does_what_it_can(manager: ControllerManager) -> None:
    ok, message = manager.switch(["admittance_controller", "nope"], ["gripper_controller"], BEST_EFFORT, None)
    assert ok
    assert "nope" in message and "claimed by arm_controller" in message
    assert states(manager)["gripper_controller"] == "inactive"
    assert states(manager)["admittance_controller"] == "inactive"


def test_strictness_zero_is_best_effort(manager: ControllerManager) -> None:
    ok, _ = manager.switch([], ["gripper_controller", "nope"], 0, None)
    assert ok
    assert states(manager)["gripper_controller"] == "inactive"


def test_unknown_names_fail_a_strict_switch_and_list_the_known_ones(manager: ControllerManager) -> None:
    ok, message = manager.switch([], ["gripper_controller", "nope"], STRICT, None)
    assert not ok
    assert "'nope'" in message and "arm_controller" in message
    assert states(manager)["gripper_controller"] == "active"


def test_leading_slashes_and_repeats_are_accepted_and_no_ops_do_nothing(manager: ControllerManager) -> None:
    arm = manager.controllers["arm_controller"]
    calls = len(arm.calls)  # type: ignore[attr-defined]
    ok, message = manager.switch(["/arm_controller", "arm_controller"], [], STRICT, None)
    assert ok
    assert message == "nothing to switch"
    assert len(arm.calls) == calls  # type: ignore[attr-defined]


def test_activate_and_deactivate_the_same_controller_is_a_problem(manager: ControllerManager) -> None:
    ok, message = manager.switch(["gripper_controller"], ["gripper_controller"], STRICT, None)
    assert not ok
    assert "both activate and deactivate" in message
