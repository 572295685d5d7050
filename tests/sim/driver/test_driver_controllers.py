"""The controller manager: list, switch (strict and best effort), and goals to inactive controllers."""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from driver_harness import ARM, GRIPPER, Sim, trajectory, wait_for

from kinema.drivers.mujoco import names as n
from kinema.transport import STATUS_ABORTED

# lab_sim's gripper controller (its config.yaml's robot.gripper.controller).
LAB_SIM_GRIPPER = "robotiq_gripper_controller"

STRICT, BEST_EFFORT = 2, 1


def test_list_controllers_reports_the_config_controllers_active(sim: Sim) -> None:
    controllers = sim.controllers()
    active = {
        n.JOINT_STATE_BROADCASTER,
        n.FORCE_TORQUE_SENSOR_BROADCASTER,
        n.JOINT_TRAJECTORY_CONTROLLER,
        LAB_SIM_GRIPPER,
    }
    inactive = {n.JOINT_TRAJECTORY_ADMITTANCE_CONTROLLER, n.VELOCITY_FORCE_CONTROLLER}
    assert set(controllers) == active | inactive
    assert {name for name, c in controllers.items() if c.state == "active"} == active
    trajectory_controller = controllers[n.JOINT_TRAJECTORY_CONTROLLER]
    assert trajectory_controller.type == "joint_trajectory_controller/JointTrajectoryController"
    assert list(trajectory_controller.claimed_interfaces) == [f"{j}/position" for j in ARM]
    assert list(controllers[LAB_SIM_GRIPPER].claimed_interfaces) == [f"{GRIPPER}/position"]
    assert list(controllers[n.JOINT_STATE_BROADCASTER].claimed_interfaces) == []


def test_switching_off_and_on_again(sim: Sim) -> None:
    response = sim.switch(deactivate=[n.JOINT_TRAJECTORY_CONTROLLER, LAB_SIM_GRIPPER])
    assert response.ok, response.message
    controllers = sim.controllers()
    assert controllers[n.JOINT_TRAJECTORY_CONTROLLER].state == "inactive"
    assert list(controllers[n.JOINT_TRAJECTORY_CONTROLLER].claimed_interfaces) == []
    assert controllers[LAB_SIM_GRIPPER].state == "inactive"
    assert controllers[n.JOINT_STATE_BROADCASTER].state == "active"
    # MoveIt Pro's objectives name controllers with a leading slash.
    response = sim.switch(activate=["/joint_trajectory_controller", LAB_SIM_GRIPPER])
    assert response.ok, response.message
    states = {name: c.state for name, c in sim.controllers().items()}
    assert states[n.JOINT_TRAJECTORY_CONTROLLER] == states[LAB_SIM_GRIPPER] == "active", states


def test_a_goal_to_an_inactive_controller_is_rejected(sim: Sim) -> None:
    assert sim.switch(deactivate=[n.JOINT_TRAJECTORY_CONTROLLER]).ok
    start = sim.joint_states.latest()
    result = sim.follow(trajectory(start, start + 0.3, 0.5)).result(10.0)
    assert result.status == STATUS_ABORTED
    assert "inactive" in result.result.error_string
    sim.settle(0.3)
    np.testing.assert_allclose(sim.joint_states.latest(), start, atol=1e-3)
    assert sim.switch(activate=[n.JOINT_TRAJECTORY_CONTROLLER]).ok
    assert sim.follow(trajectory(start, start + 0.3, 0.5)).result(30.0).succeeded


def test_a_gripper_goal_to_an_inactive_controller_is_aborted(sim: Sim) -> None:
    assert sim.switch(deactivate=[LAB_SIM_GRIPPER]).ok
    assert sim.gripper(0.7929).status == STATUS_ABORTED
    sim.settle(0.3)
    assert sim.joint_states.latest((GRIPPER,))[0] < 0.01


def test_a_strict_switch_with_an_unknown_name_changes_nothing(sim: Sim) -> None:
    response = sim.switch(deactivate=[n.JOINT_TRAJECTORY_CONTROLLER, "servo_controller"], strictness=STRICT)
    assert not response.ok
    assert "servo_controller" in response.message
    assert n.JOINT_TRAJECTORY_CONTROLLER in response.message  # the known controllers are listed
    assert sim.controllers()[n.JOINT_TRAJECTORY_CONTROLLER].state == "active"


def test_a_best_effort_switch_skips_unknown_names(sim: Sim) -> None:
    response = sim.switch(
        deactivate=[n.JOINT_TRAJECTORY_CONTROLLER, "servo_controller"], strictness=BEST_EFFORT
    )
    assert response.ok
    assert "servo_controller" in response.message
    assert sim.controllers()[n.JOINT_TRAJECTORY_CONTROLLER].state == "inactive"


def test_the_broadcaster_can_be_switched_off(sim: Sim) -> None:
    assert sim.switch(deactivate=[n.JOINT_STATE_BROADCASTER]).ok
    switched_off = sim.driver.sim_time
    wait_for(lambda: sim.driver.sim_time > switched_off + 0.5, what="0.5 s of sim time")
    time.sleep(0.5)  # let messages published before the switch drain (many, on a loaded machine)
    # Judged by stamp, not by count: a backlog published before the switch may still be arriving.
    later = [stamp for stamp in list(sim.joint_states.stamps) if stamp > switched_off + 0.02]
    assert not later, f"/joint_states stamped {later[:5]} after the switch at sim time {switched_off:.3f}"
    assert sim.switch(activate=[n.JOINT_STATE_BROADCASTER]).ok
    sim.joint_states.wait_until(sim.driver.sim_time)


def test_the_controllers_can_start_inactive(start_sim: Callable[..., Sim]) -> None:
    sim = start_sim(
        active_controllers=(n.JOINT_STATE_BROADCASTER, LAB_SIM_GRIPPER),
        inactive_controllers=(n.JOINT_TRAJECTORY_CONTROLLER,),
    )
    states = {name: c.state for name, c in sim.controllers().items()}
    assert states == {
        n.JOINT_STATE_BROADCASTER: "active",
        LAB_SIM_GRIPPER: "active",
        n.JOINT_TRAJECTORY_CONTROLLER: "inactive",
    }
