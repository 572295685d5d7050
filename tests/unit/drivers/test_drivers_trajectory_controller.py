"""The trajectory controller's logic on a fake, perfectly tracking plant (no MuJoCo)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pytest

from kinema.drivers.mujoco.execution import Execution
from kinema.drivers.mujoco.model_index import JointInfo
from kinema.drivers.mujoco.trajectory_controller import JointTrajectoryController
from kinema.drivers.mujoco.trajectory_goal import (
    GOAL_TOLERANCE_VIOLATED,
    OLD_HEADER_TIMESTAMP,
    PATH_TOLERANCE_VIOLATED,
    SUCCESSFUL,
    ToleranceDefaults,
    TrajectoryGoal,
)

DT = 0.002
NAMES = ("a", "b")


class Plant:
    """Stands in for MjData: the joints go where ctrl says, unless ``response`` says otherwise."""

    def __init__(self, response: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None) -> None:
        self.time = 0.0
        self.qpos = np.zeros(2)
        self.qvel = np.zeros(2)
        self.ctrl = np.zeros(2)
        self.response = response or (lambda ctrl, qpos: ctrl.copy())

    def step(self, controller: JointTrajectoryController) -> None:
        controller.update(self)
        moved = self.response(self.ctrl, self.qpos)
        self.qvel = (moved - self.qpos) / DT
        self.qpos = moved
        self.time += DT

    def run(self, controller: JointTrajectoryController, execution: Execution, limit: float = 10.0) -> None:
        while not execution.done.is_set() and self.time < limit:
            self.step(controller)


def make_goal(target: list[float], duration: float = 1.0, **overrides: object) -> TrajectoryGoal:
    defaults = ToleranceDefaults()
    fields: dict[str, object] = {
        "joint_names": NAMES,
        "joint_indices": np.array([0, 1]),
        "times": np.array([duration]),
        "positions": np.array([target]),
        "velocities": np.array([[0.0, 0.0]]),
        "accelerations": None,
        "start_stamp": None,
        "path_position_tolerance": np.full(2, defaults.path_position),
        "path_velocity_tolerance": np.full(2, math.inf),
        "goal_position_tolerance": np.full(2, defaults.goal_position),
        "goal_velocity_tolerance": np.full(2, defaults.goal_velocity),
        "goal_time_tolerance": defaults.goal_time,
    }
    fields.update(overrides)
    return TrajectoryGoal(**fields)  # type: ignore[arg-type]


@pytest.fixture
def controller() -> JointTrajectoryController:
    joints = [JointInfo(name, i, i, None, i) for i, name in enumerate(NAMES)]
    return JointTrajectoryController("arm", joints, np.zeros(2), DT)


def start(controller: JointTrajectoryController, plant: Plant, goal: TrajectoryGoal) -> Execution:
    execution = Execution("goal")
    controller.start(execution, goal, plant)
    return execution


def test_a_goal_is_tracked_and_succeeds(controller: JointTrajectoryController) -> None:
    plant = Plant()
    controller.activate(plant)
    execution = start(controller, plant, make_goal([0.5, -0.2]))
    plant.run(controller, execution)
    assert execution.outcome is not None
    assert execution.outcome.status == "succeeded"
    assert execution.outcome.result["error_code"] == SUCCESSFUL
    np.testing.assert_allclose(plant.qpos, [0.5, -0.2], atol=1e-3)
    assert 1.0 <= plant.time <= 1.0 + 3 * DT
    assert not controller.busy


def run_blocked(
    controller: JointTrajectoryController, blocked: Callable[[], None] = lambda: None
) -> tuple[Plant, Execution]:
    """Run a goal during which joint ``a`` cannot pass 0.2 (``blocked()`` is called while it is held)."""

    def response(ctrl: np.ndarray, qpos: np.ndarray) -> np.ndarray:
        if ctrl[0] > 0.2:
            blocked()
        return np.array([min(ctrl[0], 0.2), ctrl[1]])

    plant = Plant(response)
    controller.activate(plant)
    execution = start(controller, plant, make_goal([1.0, 0.5]))
    plant.run(controller, execution)
    return plant, execution


def test_a_blocked_joint_violates_the_path_tolerance_and_the_arm_holds(
    controller: JointTrajectoryController,
) -> None:
    plant, execution = run_blocked(controller)
    outcome = execution.outcome
    assert outcome is not None
    assert outcome.status == "aborted"
    assert outcome.result["error_code"] == PATH_TOLERANCE_VIOLATED
    assert "a off by" in outcome.result["error_string"]
    assert "b off by" not in outcome.result["error_string"]
    assert "touches" not in outcome.result["error_string"]  # (this controller cannot tell)
    np.testing.assert_allclose(plant.ctrl, plant.qpos)


def test_an_abort_names_what_the_robot_touches() -> None:
    # A joint held back by something in the way: the message says what the robot touches then.
    joints = [JointInfo(name, i, i, None, i) for i, name in enumerate(NAMES)]
    touching: dict[str, list[str]] = {"now": []}
    controller = JointTrajectoryController(
        "arm", joints, np.zeros(2), DT, touching=lambda data: touching["now"]
    )
    _, execution = run_blocked(
        controller, lambda: touching.update(now=["cube (left_finger, right_finger)", "tray (wrist)"])
    )
    outcome = execution.outcome
    assert outcome is not None
    message = outcome.result["error_string"]
    assert message.endswith("; the robot touches cube (left_finger, right_finger), tray (wrist)"), message
    # Touching nothing, the message says nothing of it.
    plant, touching["now"] = Plant(lambda ctrl, qpos: ctrl + np.array([0.0, 0.05])), []
    controller.activate(plant)
    execution = start(controller, plant, make_goal([0.3, 0.3], goal_time_tolerance=0.25))
    plant.run(controller, execution)
    assert execution.outcome is not None
    assert "touches" not in execution.outcome.result["error_string"]


def test_an_offset_at_the_end_violates_the_goal_tolerance_after_the_goal_time(
    controller: JointTrajectoryController,
) -> None:
    plant = Plant(lambda ctrl, qpos: ctrl + np.array([0.0, 0.05]))
    controller.activate(plant)
    execution = start(controller, plant, make_goal([0.3, 0.3], goal_time_tolerance=0.25))
    plant.run(controller, execution)
    assert execution.outcome is not None
    assert execution.outcome.result["error_code"] == GOAL_TOLERANCE_VIOLATED
    assert "b off by +0.0500" in execution.outcome.result["error_string"]
    assert plant.time == pytest.approx(1.25, abs=3 * DT)


def test_cancel_holds_where_the_joints_are_at_once(controller: JointTrajectoryController) -> None:
    plant = Plant()
    controller.activate(plant)
    execution = start(controller, plant, make_goal([1.0, 1.0]))
    while plant.time < 0.5:
        plant.step(controller)
    here = plant.qpos.copy()
    controller.cancel(execution, plant)
    assert execution.outcome is not None
    assert execution.outcome.status == "canceled"
    assert "canceled at sim time 0.50" in execution.outcome.result["error_string"]
    for _ in range(50):
        plant.step(controller)
    np.testing.assert_allclose(plant.qpos, here)


def test_an_inactive_controller_aborts_the_goal_and_commands_nothing(
    controller: JointTrajectoryController,
) -> None:
    plant = Plant()
    execution = start(controller, plant, make_goal([1.0, 1.0]))
    assert execution.outcome is not None
    assert execution.outcome.status == "aborted"
    assert "inactive" in execution.outcome.result["error_string"]
    plant.step(controller)
    np.testing.assert_allclose(plant.ctrl, [0.0, 0.0])


def test_a_new_goal_preempts_and_starts_from_the_current_command(
    controller: JointTrajectoryController,
) -> None:
    plant = Plant()
    controller.activate(plant)
    first = start(controller, plant, make_goal([1.0, 1.0]))
    while plant.time < 0.5:
        plant.step(controller)
    midway = plant.ctrl.copy()
    second = start(controller, plant, make_goal([0.0, 0.0]))
    assert first.outcome is not None and first.outcome.status == "aborted"
    assert "preempted" in first.outcome.result["error_string"]
    plant.step(controller)
    np.testing.assert_allclose(plant.ctrl, midway, atol=0.01)  # no jump: the new goal starts here
    plant.run(controller, second)
    assert second.outcome is not None and second.outcome.status == "succeeded"


def test_stamps_in_the_past_are_refused_and_in_the_future_wait(controller: JointTrajectoryController) -> None:
    plant = Plant()
    controller.activate(plant)
    plant.time = 5.0
    stale = start(controller, plant, make_goal([1.0, 1.0], start_stamp=3.0))
    assert stale.outcome is not None
    assert stale.outcome.result["error_code"] == OLD_HEADER_TIMESTAMP
    later = start(controller, plant, make_goal([1.0, 1.0], start_stamp=5.5))
    while plant.time < 5.45:
        plant.step(controller)
    np.testing.assert_allclose(plant.qpos, [0.0, 0.0])
    plant.run(controller, later)
    assert later.outcome is not None and later.outcome.status == "succeeded"
    assert plant.time == pytest.approx(6.5, abs=3 * DT)


@pytest.mark.parametrize("event", ["deactivate", "on_state_reset"])
def test_deactivation_and_state_resets_abort_the_goal(
    controller: JointTrajectoryController, event: str
) -> None:
    plant = Plant()
    controller.activate(plant)
    execution = start(controller, plant, make_goal([1.0, 1.0]))
    plant.step(controller)
    getattr(controller, event)(plant)
    assert execution.outcome is not None and execution.outcome.status == "aborted"
    assert not controller.busy


def test_joints_a_preempting_goal_leaves_out_hold_their_last_desired_position() -> None:
    joints = [JointInfo(name, i, i, None, i) for i, name in enumerate(NAMES)]
    controller = JointTrajectoryController("arm", joints, np.full(2, 0.1), DT)  # with velocity feed-forward
    plant = Plant()
    controller.activate(plant)
    # The fake plant goes where ctrl says, feed-forward included: allow for that offset on the path.
    first = start(controller, plant, make_goal([1.0, 1.0], path_position_tolerance=np.full(2, 1.0)))
    while plant.time < 0.5:
        plant.step(controller)
    moving_b = plant.ctrl[1]
    partial = make_goal([0.0], joint_names=("a",), joint_indices=np.array([0]), velocities=None)
    partial = replace(
        partial,
        path_position_tolerance=np.full(1, 1.0),
        path_velocity_tolerance=np.full(1, math.inf),
        goal_position_tolerance=np.full(1, 0.01),
        goal_velocity_tolerance=np.full(1, 0.05),
    )
    execution = start(controller, plant, partial)
    assert first.outcome is not None and "preempted" in first.outcome.result["error_string"]
    plant.run(controller, execution)
    assert execution.outcome is not None and execution.outcome.status == "succeeded"
    # b holds where the first goal wanted it when preempted: its ctrl lost the feed-forward term.
    assert plant.ctrl[1] < moving_b
    assert plant.qpos[1] == pytest.approx(plant.ctrl[1])
    assert 0.3 < plant.ctrl[1] < 0.7


def _from_now(points: list[list[float]], times: list[float]) -> TrajectoryGoal:
    """A goal whose first point is at time 0 (a planner's start state), without velocities."""
    return make_goal(points[-1], times=np.array(times), positions=np.array(points), velocities=None)


def test_a_goal_starting_off_the_arm_is_led_in_from_where_the_arm_is(
    controller: JointTrajectoryController,
) -> None:
    # Planned from [0, 0] while the arm went on to [0.3, -0.2]: starting at the first point would be
    # 0.3 off at once, beyond the 0.1 path tolerance ("0.000 s into the trajectory").
    plant = Plant()
    plant.qpos[:] = plant.ctrl[:] = [0.3, -0.2]
    controller.activate(plant)
    execution = start(controller, plant, _from_now([[0.0, 0.0], [0.5, 0.5]], [0.0, 1.0]))
    plant.step(controller)
    desired_at_start = plant.ctrl.copy()
    plant.run(controller, execution)
    assert execution.outcome is not None and execution.outcome.status == "succeeded", execution.outcome
    np.testing.assert_allclose(desired_at_start, [0.3, -0.2], atol=1e-6)
    np.testing.assert_allclose(plant.qpos, [0.5, 0.5], atol=0.01)
    assert plant.time > 1.0 + 0.1, "the lead-in adds time before the planned trajectory"


def test_a_goal_starting_where_the_arm_rests_keeps_its_timing(controller: JointTrajectoryController) -> None:
    plant = Plant()
    controller.activate(plant)
    execution = start(controller, plant, _from_now([[0.0, 0.0], [0.5, 0.5]], [0.0, 1.0]))
    plant.run(controller, execution)
    assert execution.outcome is not None and execution.outcome.status == "succeeded"
    assert plant.time == pytest.approx(1.0, abs=0.01)
