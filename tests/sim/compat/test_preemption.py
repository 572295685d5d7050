"""Preemption is safe: a new objective started while another moves the arm never aborts on the path
tolerance, and the looping pick and place runs again after a cancel left the cube in the tray."""

from __future__ import annotations

import numpy as np
import pytest
from compat_cell import PICK_POSITION, PLACE_POSITION, Cell, wait_for
from objective_checks import CYCLE_TIMEOUT_WALL, near, run_and_expect_success

from kinema.sdk import ObjectiveHandle

pytestmark = pytest.mark.slow

PREEMPTIONS = 50
# Two targets far enough apart that every motion between them is a real swing of the arm.
TARGETS = ("Look at Table", "3 Waypoint Mid Point")


@pytest.fixture(scope="module")
def cell(start_cell) -> Cell:
    cell = start_cell(objectives=None)
    cell.record_joint_states()
    return cell


def _moving(cell: Cell, since: float, threshold: float = 0.05) -> bool:
    stamps, _, velocities = cell.joint_history()
    recent = stamps > since
    return bool(recent.any() and np.abs(velocities[recent][-1]).max() > threshold)


def _move_to(cell: Cell, waypoint: str) -> ObjectiveHandle:
    xml = (
        f'<root BTCPP_format="4" main_tree_to_execute="To {waypoint}"><BehaviorTree ID="To {waypoint}">'
        f'<SubTree ID="Move to Waypoint" waypoint_name="{waypoint}"/></BehaviorTree></root>'
    )
    return cell.client.start(xml=xml)


def test_preempting_a_moving_arm_50_times_never_aborts(cell: Cell) -> None:
    run_and_expect_success(cell, "Open Gripper")
    previous = _move_to(cell, TARGETS[0])
    outcomes = []
    for i in range(PREEMPTIONS):
        started = cell.joint_history()[0][-1]
        # Preempt in the middle of the motion: once the arm moves (planning is over, the trajectory runs).
        wait_for(lambda s=started, p=previous: _moving(cell, s) or p.done, 30.0, f"the arm to move ({i + 1})")
        current = _move_to(cell, TARGETS[(i + 1) % 2])
        result = previous.result(30.0)
        outcomes.append(result)
        # At max sim speed a motion may end before its successor is loaded; it must never fail.
        assert result.cancelled or result.succeeded, f"preemption {i + 1}: the objective ended {result}"
        previous = current
    last = previous.result(60.0)
    assert last.succeeded, f"the last motion, never preempted, ended {last}"
    preempted = sum(result.cancelled for result in outcomes)
    assert preempted >= PREEMPTIONS // 2, f"only {preempted} of {PREEMPTIONS} motions were preempted mid-way"


def test_pick_and_place_starts_again_after_a_cancel_left_the_cube_in_the_tray(cell: Cell) -> None:
    run_and_expect_success(cell, "Reset MuJoCo Scene")
    assert near(cell.cube(), PICK_POSITION), cell.cube()
    handle = cell.client.start("3 Waypoints Pick and Place")
    wait_for(lambda: near(cell.cube(), PLACE_POSITION), CYCLE_TIMEOUT_WALL, "the cube to reach the tray")
    cell.client.cancel()
    assert handle.result(30.0).cancelled
    assert near(cell.cube(), PLACE_POSITION), f"the cube should lie in the tray: {cell.cube()}"
    # What the tutorial says to do: put the scene back, then start the loop again.
    run_and_expect_success(cell, "Reset MuJoCo Scene")
    assert near(cell.cube(), PICK_POSITION), f"the reset left the cube at {cell.cube()}"
    handle = cell.client.start("3 Waypoints Pick and Place")
    try:
        wait_for(lambda: near(cell.cube(), PLACE_POSITION), CYCLE_TIMEOUT_WALL, "the cube to reach the tray")
        assert not handle.done, handle.result(0)
    finally:
        cell.client.cancel()
    assert handle.result(30.0).cancelled
