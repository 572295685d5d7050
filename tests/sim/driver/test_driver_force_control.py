"""The wrist force/torque sensor, the velocity-force controller and the admittance trajectory controller."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
import pytest
from driver_harness import ARM, Sim, trajectory, wait_for

from kinema.config import WaypointStore, resolve_config
from kinema.drivers.mujoco import MujocoDriver
from kinema.drivers.mujoco import names as n
from kinema.errors import DriverError
from kinema.transport import STATUS_ABORTED

GRAVITY = 9.81
TOOL_MASS = 0.72  # kg below the sensor: the gripper and the wrist camera's mount
TABLE_TOP = 0.474


def _vfc_start() -> np.ndarray:
    path = resolve_config("lab_sim").waypoints_path
    assert path is not None
    joints = WaypointStore(path).get("VFC Start").joint_positions()
    return np.array([joints[j] for j in ARM])


def _grasp(sim: Sim) -> np.ndarray:
    driver = sim.driver
    site = int(driver.model.site("grasp_site").id)
    return driver.simulation.call(lambda: driver.data.site_xpos[site].copy())


def _go_to_vfc_start(sim: Sim, action: str = n.FOLLOW_JOINT_TRAJECTORY_ACTION) -> None:
    start = sim.joint_states.latest()
    client = sim.action(action, n.FOLLOW_JOINT_TRAJECTORY_TYPE)
    assert client.send_goal(trajectory(start, _vfc_start(), 2.0), timeout=10.0).result(60.0).succeeded
    sim.settle(0.3)


def _command(velocity_z: float, *, force_axes: str = "", gain: float = 0.01) -> dict[str, Any]:
    axes = ("x", "y", "z", "rx", "ry", "rz")
    return {
        "twist": {"linear": {"z": velocity_z}},
        "velocity_controlled_axes": {axis: axis == "z" and not force_axes for axis in axes},
        "force_controlled_axes": {axis: axis in force_axes for axis in axes},
        "wrench_gain": gain,
    }


def test_the_wrist_sensor_reads_the_tools_weight_in_tool0(sim: Sim) -> None:
    wrenches: list[Any] = []
    sim.node.create_subscription(n.WRENCH_TYPE, n.WRENCH_TOPIC, wrenches.append)
    wait_for(lambda: len(wrenches) > 5, what="wrenches on /force_torque_sensor_broadcaster/wrench")
    message = wrenches[-1]
    assert message.header.frame_id == "tool0"
    force = np.array([message.wrench.force.x, message.wrench.force.y, message.wrench.force.z])
    # The arm holds the tool up: MuJoCo's reading is the force on the tool, the tool's weight upward.
    assert abs(np.linalg.norm(force) - TOOL_MASS * GRAVITY) < 0.3, force


def test_velocity_commands_move_the_grasp_frame_and_it_stops_when_they_stop(
    start_sim: Callable[..., Sim],
) -> None:
    sim = start_sim(sim_speed=1.0)  # commands come at wall-clock 50 Hz: keep sim time with them
    _go_to_vfc_start(sim)
    assert sim.switch(activate=[n.VELOCITY_FORCE_CONTROLLER], deactivate=[n.JOINT_TRAJECTORY_CONTROLLER]).ok
    zero = sim.service(n.ZERO_FTS_SERVICE, n.TRIGGER_TYPE).call(timeout=10.0)
    assert zero.success and "zeroed" in zero.message
    publisher = sim.node.create_publisher(n.VELOCITY_FORCE_COMMAND_TYPE, n.VELOCITY_FORCE_COMMAND_TOPIC)
    wait_for(lambda: sim.node.graph().subscriptions(n.VELOCITY_FORCE_COMMAND_TOPIC), what="the controller")
    before, t0 = _grasp(sim), sim.driver.sim_time
    end = time.monotonic() + 1.0
    while time.monotonic() < end:  # grasp_link's z points down: +z is toward the table
        publisher.publish(_command(0.05))
        time.sleep(0.02)
    moved, elapsed = _grasp(sim) - before, sim.driver.sim_time - t0
    assert abs(moved[0]) < 0.005 and abs(moved[1]) < 0.005, moved
    # 5 cm/s for the time the commands came (less the 2 m/s^2 ramp), plus at most the 0.2 s timeout's travel.
    assert 0.05 * elapsed - 0.02 <= -moved[2] <= 0.05 * elapsed + 0.012, (moved, elapsed)
    # No more commands: after the 0.2 s command timeout the arm stops and holds.
    sim.settle(0.4)
    stopped = _grasp(sim)
    sim.settle(0.5)
    assert np.abs(_grasp(sim) - stopped).max() < 0.001


def test_force_control_gives_way_to_a_push(start_sim: Callable[..., Sim]) -> None:
    """Force-controlled axes with a zero wrench move the tool along a push, as Force Relaxation relies on."""
    sim = start_sim(sim_speed=1.0)
    _go_to_vfc_start(sim)
    assert sim.switch(activate=[n.VELOCITY_FORCE_CONTROLLER], deactivate=[n.JOINT_TRAJECTORY_CONTROLLER]).ok
    publisher = sim.node.create_publisher(n.VELOCITY_FORCE_COMMAND_TYPE, n.VELOCITY_FORCE_COMMAND_TOPIC)
    wait_for(lambda: sim.node.graph().subscriptions(n.VELOCITY_FORCE_COMMAND_TOPIC), what="the controller")
    driver = sim.driver
    body = int(driver.model.body("grasp_link").id)
    before = _grasp(sim)
    driver.simulation.call(
        lambda: driver.data.xfrc_applied.__setitem__((body, slice(0, 3)), [0.0, 15.0, 0.0])
    )
    try:
        end = time.monotonic() + 1.0
        while time.monotonic() < end:
            publisher.publish(_command(0.0, force_axes="xyz"))
            time.sleep(0.02)
    finally:
        driver.simulation.call(lambda: driver.data.xfrc_applied.__setitem__((body, slice(0, 3)), 0.0))
    moved = _grasp(sim) - before
    # 15 N (13 N past the 2 N deadband) at 0.01 m/s per N: about 0.13 m/s along +y, the push's direction.
    assert moved[1] > 0.05, moved
    assert abs(moved[2]) < 0.02, moved


def test_the_admittance_controller_aborts_a_trajectory_that_presses_too_hard(sim: Sim) -> None:
    _go_to_vfc_start(sim)
    assert sim.switch(
        activate=[n.JOINT_TRAJECTORY_ADMITTANCE_CONTROLLER], deactivate=[n.JOINT_TRAJECTORY_CONTROLLER]
    ).ok
    from kinema.motion import RobotDescription, fk
    from kinema.motion.inverse_kinematics import ik

    model = RobotDescription.lab_sim().load_model()
    seed = model.configuration(dict(zip(ARM, _vfc_start(), strict=True)))
    target = fk(model, seed, "grasp_link")
    target[2, 3] = TABLE_TOP - 0.05  # 5 cm into the table
    into_table = ik(model, target, seed, group="manipulator", frame="grasp_link")
    columns = [model.joint_names.index(j) for j in ARM]
    client = sim.action(n.FOLLOW_JOINT_TRAJECTORY_ADMITTANCE_ACTION, n.FOLLOW_JOINT_TRAJECTORY_TYPE)
    start = sim.joint_states.latest()
    result = client.send_goal(trajectory(start, into_table[columns], 3.0), timeout=10.0).result(60.0)
    assert result.status == STATUS_ABORTED
    assert "force/torque threshold exceeded" in result.result.error_string, result.result.error_string
    assert _grasp(sim)[2] > TABLE_TOP  # stopped on the table, not through it


def _admittance(stiffness: float, axes: str = "xyz") -> dict[str, Any]:
    """Admittance parameters: a 1 kg, critically damped spring of ``stiffness`` N/m on ``axes``."""
    vector = {"x": 1.0, "y": 1.0, "z": 1.0}
    return {
        "control_frame": "grasp_site",
        "selected_axes": {axis: axis in axes for axis in ("x", "y", "z", "rx", "ry", "rz")},
        "mass_position": vector,
        "mass_rotation": vector,
        "stiffness_position": {"x": stiffness, "y": stiffness, "z": stiffness},
        "stiffness_rotation": vector,
        "damping_ratio_position": vector,
        "damping_ratio_rotation": vector,
        "joint_damping": 1.0,
    }


def _push(sim: Sim, force: tuple[float, float, float]) -> None:
    """Apply ``force`` (N, world frame) to grasp_link until the next call."""
    driver = sim.driver
    body = int(driver.model.body("grasp_link").id)
    driver.simulation.call(lambda: driver.data.xfrc_applied.__setitem__((body, slice(0, 3)), force))


def _hold_under_push(sim: Sim, goal: dict[str, Any], type_name: str, push: float) -> tuple[Any, np.ndarray]:
    """From VFC Start, push grasp_link along world +y with ``push`` N while ``goal`` (a 3 s stationary
    trajectory) runs on the admittance controller; returns the result and how far grasp_site moved."""
    _go_to_vfc_start(sim, n.FOLLOW_JOINT_TRAJECTORY_ADMITTANCE_ACTION)
    before = _grasp(sim)
    client = sim.action(n.FOLLOW_JOINT_TRAJECTORY_ADMITTANCE_ACTION, type_name)
    here = sim.joint_states.latest()
    _push(sim, (0.0, push, 0.0))
    try:
        result = client.send_goal({**trajectory(here, here, 3.0), **goal}, timeout=10.0).result(60.0)
        moved = _grasp(sim) - before
    finally:
        _push(sim, (0.0, 0.0, 0.0))
    return result, moved


@pytest.mark.slow  # five goals of several seconds of sim time each
def test_the_admittance_controller_yields_to_a_push_in_proportion_to_its_stiffness(sim: Sim) -> None:
    assert sim.switch(
        activate=[n.JOINT_TRAJECTORY_ADMITTANCE_CONTROLLER], deactivate=[n.JOINT_TRAJECTORY_CONTROLLER]
    ).ok
    zero = sim.service(
        n.admittance_zero_fts_service(n.JOINT_TRAJECTORY_ADMITTANCE_CONTROLLER, "tool0"), n.TRIGGER_TYPE
    ).call(timeout=10.0)
    assert zero.success and "zeroed" in zero.message
    with_admittance = n.FOLLOW_JOINT_TRAJECTORY_WITH_ADMITTANCE_TYPE
    push = 10.0
    moved = {}
    for stiffness in (400.0, 100.0):
        result, moved[stiffness] = _hold_under_push(
            sim, {"admittance_parameters": _admittance(stiffness)}, with_admittance, push
        )
        assert result.succeeded, result.result.error_string
        # Along the push, by push / stiffness (plus the position servos' own give, a few mm at most) ...
        assert moved[stiffness][1] == pytest.approx(push / stiffness, rel=0.25, abs=0.004), moved
        # ... and nowhere else.
        assert abs(moved[stiffness][0]) < 0.005 and abs(moved[stiffness][2]) < 0.005, moved
    assert 3.0 < moved[100.0][1] / moved[400.0][1] < 5.0, moved
    # Only the selected axes give way: compliant along z alone, the same push moves the tool little.
    result, sideways = _hold_under_push(
        sim, {"admittance_parameters": _admittance(100.0, axes="z")}, with_admittance, push
    )
    assert result.succeeded and sideways[1] < 0.3 * moved[100.0][1], sideways
    # A plain FollowJointTrajectory goal on the same controller is tracked rigidly: the tool gives only as
    # much as the position servos do (which fails its goal tolerance, as on joint_trajectory_controller).
    _, rigid = _hold_under_push(sim, {}, n.FOLLOW_JOINT_TRAJECTORY_TYPE, push)
    assert rigid[1] < 0.3 * moved[100.0][1], rigid


def test_a_goals_force_threshold_aborts_it_and_bad_parameters_are_rejected(sim: Sim) -> None:
    assert sim.switch(
        activate=[n.JOINT_TRAJECTORY_ADMITTANCE_CONTROLLER], deactivate=[n.JOINT_TRAJECTORY_CONTROLLER]
    ).ok
    with_admittance = n.FOLLOW_JOINT_TRAJECTORY_WITH_ADMITTANCE_TYPE
    compliant = {"admittance_parameters": _admittance(400.0)}
    threshold = {"absolute_force_torque_threshold": [5.0, 5.0, 5.0, 10.0, 10.0, 10.0]}
    result, _ = _hold_under_push(sim, {**compliant, **threshold}, with_admittance, 10.0)
    assert result.status == STATUS_ABORTED
    assert "force/torque threshold exceeded" in result.result.error_string, result.result.error_string
    assert "force y" in result.result.error_string or "force x" in result.result.error_string
    # The default threshold (45 N) lets the same push through.
    result, _ = _hold_under_push(sim, compliant, with_admittance, 10.0)
    assert result.succeeded, result.result.error_string
    bad = _admittance(100.0)
    bad["mass_position"] = {"x": 0.0, "y": 1.0, "z": 1.0}
    result, _ = _hold_under_push(sim, {"admittance_parameters": bad}, with_admittance, 0.0)
    assert result.status == STATUS_ABORTED
    assert "mass x = 0 (must be positive)" in result.result.error_string, result.result.error_string


def test_the_controllers_ros2_control_parameters_set_its_defaults(start_sim: Callable[..., Sim]) -> None:
    """MoveIt Pro's ros2_control parameters of the admittance controller (default threshold, ee_frame)
    reach the simulated one: here a 5 N default threshold stops a 10 N push no goal limits."""
    from kinema.config import resolve_config
    from kinema.config.cell import CellSettings

    controllers = dict(CellSettings.from_config(resolve_config("lab_sim")).controllers)
    name = n.JOINT_TRAJECTORY_ADMITTANCE_CONTROLLER
    controllers[name] = replace(
        controllers[name],
        parameters={"default_absolute_force_torque_threshold": [5.0, 5.0, 5.0, 10.0, 10.0, 10.0]},
    )
    sim = start_sim(controllers=controllers)
    assert sim.switch(activate=[name], deactivate=[n.JOINT_TRAJECTORY_CONTROLLER]).ok
    compliant = {"admittance_parameters": _admittance(400.0)}
    result, _ = _hold_under_push(sim, compliant, n.FOLLOW_JOINT_TRAJECTORY_WITH_ADMITTANCE_TYPE, 10.0)
    assert result.status == STATUS_ABORTED
    assert "(limit 5)" in result.result.error_string, result.result.error_string
    controllers[name] = replace(
        controllers[name], parameters={"default_absolute_force_torque_threshold": [5.0]}
    )
    bad = sim.driver.settings.with_changes(controllers=controllers)
    with pytest.raises(DriverError, match="default_absolute_force_torque_threshold must be six positive"):
        MujocoDriver(sim.driver.session, bad)  # refused while building its controllers, before serving
