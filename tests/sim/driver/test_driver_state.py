"""Setting the simulation state (joints, keyframes), free bodies, keyframes, /clock and /joint_states."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from driver_harness import ARM, GRIPPER, Sim, trajectory, wait_for

from kinema.drivers.mujoco import names as n
from kinema.drivers.mujoco.simulation import MAX_LAG
from kinema.transport import STATUS_ABORTED

# lab_sim's gripper controller (its config.yaml's robot.gripper.controller).
LAB_SIM_GRIPPER = "robotiq_gripper_controller"

# "Reset MuJoCo Robot" (MoveIt Pro's lab_sim objective) sets exactly this state.
RESET_STATE = dict(zip(ARM, (0.0, 0.0, -1.57, 0.0, 0.0, 0.0, 0.0), strict=True))
DEFAULT_ARM = np.array([0.0, 0.0, -2.0, 2.0, -1.5708, -1.5708, 0.0])
CUBE_START = np.array([-0.30, 0.62, 0.499])


def bodies(sim: Sim) -> dict[str, np.ndarray]:
    response = sim.service(n.BODIES_SERVICE, n.BODIES_TYPE).call(timeout=10.0)
    return {
        b.name: np.array([b.pose.position.x, b.pose.position.y, b.pose.position.z]) for b in response.bodies
    }


def test_joint_states_use_moveit_pros_names_at_100_hz_of_sim_time(sim: Sim) -> None:
    sim.settle(0.3)
    assert sim.joint_states.names[: len(ARM) + 1] == [*ARM, GRIPPER]
    stamps, _ = sim.joint_states.history()
    assert np.allclose(np.diff(stamps[-20:]), 0.01, atol=1e-6)


def test_the_reset_objectives_flow_moves_the_arm_and_it_stays(sim: Sim) -> None:
    """ListControllers → deactivate → SetMujocoState → activate, as "Reset MuJoCo Robot" does."""
    active = [name for name, c in sim.controllers().items() if c.state == "active" and c.claimed_interfaces]
    assert sim.switch(deactivate=active).ok
    response = sim.set_state(**RESET_STATE)
    assert response.success, response.message
    assert sim.switch(activate=active).ok
    sim.settle(1.0)
    np.testing.assert_allclose(sim.joint_states.latest(), list(RESET_STATE.values()), atol=2e-3)


def test_setting_joints_with_the_controllers_active_holds_them_there(sim: Sim) -> None:
    assert sim.set_state(**RESET_STATE).success
    sim.settle(1.0)
    np.testing.assert_allclose(sim.joint_states.latest(), list(RESET_STATE.values()), atol=2e-3)


def test_setting_the_gripper_joint_moves_the_fingers_with_it(sim: Sim) -> None:
    assert sim.set_state(robotiq_85_left_knuckle_joint=0.4).success
    sim.settle(0.5)
    knuckle, left, right = sim.joint_states.latest(
        (GRIPPER, "robotiq_85_left_finger_joint", "robotiq_85_right_finger_joint")
    )
    assert knuckle == pytest.approx(0.4, abs=0.01)
    assert left == pytest.approx(0.4 * 0.0425 / 0.7929, abs=1e-3)
    assert right == pytest.approx(left, abs=1e-3)


def test_a_keyframe_resets_robot_and_objects_and_time_runs_on(sim: Sim, pick_pose: dict[str, float]) -> None:
    # Grasp the cube and carry it 20 cm along the rail, so the reset has an object to put back.
    assert sim.set_state(**pick_pose).success
    sim.settle(0.3)
    assert sim.gripper(0.7929).result.stalled
    start = sim.joint_states.latest()
    assert (
        sim.follow(trajectory(start, start + np.array([-0.2, 0, 0, 0, 0, 0, 0]), 1.0)).result(30.0).succeeded
    )
    sim.settle(0.3)
    assert np.linalg.norm(bodies(sim)["cube"] - CUBE_START) > 0.1
    before_reset = sim.joint_states.latest_stamp()
    response = sim.set_state(keyframe="default")
    assert response.success, response.message
    sim.settle(0.5)
    np.testing.assert_allclose(sim.joint_states.latest(), DEFAULT_ARM, atol=2e-3)
    np.testing.assert_allclose(bodies(sim)["cube"], CUBE_START, atol=2e-3)
    stamps, _ = sim.joint_states.history()
    assert np.all(np.diff(stamps) > 0), "/joint_states stamps went backwards"
    assert stamps[-1] > before_reset


def test_a_running_trajectory_is_aborted_by_a_state_reset(sim: Sim) -> None:
    start = sim.joint_states.latest()
    handle = sim.follow(trajectory(start, start + 0.4, 5.0))
    sim.settle(0.2)
    assert sim.set_state(keyframe="default").success
    result = handle.result(10.0)
    assert result.status == STATUS_ABORTED
    assert "reset" in result.result.error_string
    sim.settle(0.5)
    np.testing.assert_allclose(sim.joint_states.latest(), DEFAULT_ARM, atol=2e-3)


@pytest.mark.parametrize(
    ("request_fields", "expected"),
    [
        ({"keyframe": "homme"}, "home"),
        ({"joint_state": {"name": ["elbow"], "position": [0.1]}}, "elbow_joint"),
        ({"joint_state": {"name": ["shoulder_lift_joint"], "position": [1.0]}}, "outside its limits"),
        ({"joint_state": {"name": ["elbow_joint", "wrist_1_joint"], "position": [0.1]}}, "2 names but 1"),
        ({}, "nothing to set"),
    ],
)
def test_bad_set_state_requests_fail_with_a_reason(
    sim: Sim, request_fields: dict[str, Any], expected: str
) -> None:
    before = sim.joint_states.latest()
    response = sim.service(n.SET_STATE_SERVICE, n.SET_STATE_TYPE).call(request_fields, timeout=10.0)
    assert not response.success
    assert expected in response.message
    sim.settle(0.2)
    np.testing.assert_allclose(sim.joint_states.latest(), before, atol=1e-3)


def test_bodies_lists_the_free_objects_with_their_world_positions(sim: Sim) -> None:
    found = bodies(sim)
    assert {"cube", "tag_block"} <= set(found), sorted(found)
    np.testing.assert_allclose(found["cube"], CUBE_START, atol=2e-3)
    assert found["tag_block"][2] == pytest.approx(0.514, abs=2e-3), "the tagged block stands on the table"


def test_keyframes_lists_the_models_keyframes(sim: Sim) -> None:
    response = sim.service(n.KEYFRAMES_SERVICE, n.KEYFRAMES_TYPE).call(timeout=10.0)
    assert list(response.names) == ["default", "home"]
    assert response.initial == "default"


def test_the_scene_state_topic_carries_qpos_and_free_bodies(sim: Sim) -> None:
    received: list[Any] = []
    sim.node.create_subscription(n.SCENE_STATE_TYPE, n.SCENE_STATE_TOPIC, received.append, latched=True)
    wait_for(lambda: received, what="a scene state")
    scene = received[-1]
    assert len(scene.qpos) == sim.driver.model.nq
    names = [b.name for b in scene.bodies]
    assert names[0] == "cube" and "tag_block" in names, names  # in the model's order


def test_clock_runs_faster_than_wall_time_at_max_speed(sim: Sim) -> None:
    clock: list[float] = []
    sim.node.create_subscription(
        n.CLOCK_TYPE, n.CLOCK_TOPIC, lambda m: clock.append(m.clock.sec + m.clock.nanosec * 1e-9)
    )
    wait_for(lambda: clock, what="/clock")
    wall_start, sim_start = time.monotonic(), clock[-1]
    # Unpaced, the sim soon runs ahead of the wall clock even when the machine starves it for a moment; a
    # sim paced at real time never gets 1.5x ahead however long this waits.
    wait_for(
        lambda: (
            time.monotonic() - wall_start > 0.5
            and clock[-1] - sim_start > 1.5 * (time.monotonic() - wall_start)
        ),
        timeout=60.0,
        what="sim time 1.5x ahead of the wall clock",
    )
    assert np.all(np.diff(clock) > 0)


def test_clock_never_runs_ahead_of_wall_time_at_real_time(start_sim: Callable[..., Sim]) -> None:
    sim = start_sim(sim_speed=1.0)
    # Read from the physics thread's own clock: message stamps arrive late under load, which would make
    # the simulation look ahead when the first stamp was stale.
    first, wall_start = sim.driver.sim_time, time.monotonic()
    time.sleep(1.5)
    sim_elapsed, wall_elapsed = sim.driver.sim_time - first, time.monotonic() - wall_start
    # The paced simulation may have been up to MAX_LAG behind at the first reading and caught up since
    # (under load it is), plus a publish period (10 ms at most): sim time advances a period at a time.
    # Running free, or even 1.2x fast, would pass that within the 1.5 s.
    slack = MAX_LAG + 0.02
    assert sim_elapsed <= wall_elapsed + slack, f"{sim_elapsed:.3f} s of sim time in {wall_elapsed:.3f} s"


def test_everything_the_driver_says_it_serves_is_on_the_graph(sim: Sim) -> None:
    served = sim.driver.interfaces()
    assert {(i.kind, i.name) for i in served} >= {
        ("topic", n.CLOCK_TOPIC),
        ("topic", n.JOINT_STATES_TOPIC),
        ("action", n.FOLLOW_JOINT_TRAJECTORY_ACTION),
        ("action", n.gripper_command_action(LAB_SIM_GRIPPER)),
        ("service", n.LIST_CONTROLLERS_SERVICE),
        ("service", n.SWITCH_CONTROLLERS_SERVICE),
        ("service", n.SET_STATE_SERVICE),
    }

    def all_there() -> bool:
        graph = sim.node.graph()
        topics, services, actions = graph.topics(), graph.services(), graph.actions()
        found = {"topic": topics, "service": services, "action": actions}
        return all(i.type_name in found[i.kind].get(i.name, []) for i in served)

    wait_for(all_there, what="every served interface on the graph")
