"""The checks the compatibility tests run against any objective library (MoveIt Pro's or Kinema's)."""

from __future__ import annotations

import time

import numpy as np
from compat_cell import PICK_POSITION, PLACE_POSITION, TOLERANCE, Cell, wait_for

# Sim seconds a full pick-and-place cycle may take at most, with margin (it takes about 30 s).
CYCLE_TIMEOUT_WALL = 90.0

# The lab_sim objectives of MoveIt Pro that both libraries (MoveIt Pro's copy and Kinema's) provide.
MOVEIT_PRO_OBJECTIVES = (
    "3 Waypoints Pick and Place",
    "Close Gripper",
    "Open Gripper",
    "Look at Table",
    "Reset MuJoCo Robot",
    "Move to Waypoint",
    "Move to Joint State",
)


def near(position: np.ndarray, target: np.ndarray) -> bool:
    """Within TOLERANCE (2 cm) of ``target``."""
    return bool(np.linalg.norm(position - target) < TOLERANCE)


def run_pick_and_place_two_placements(cell: Cell) -> None:
    """Start "3 Waypoints Pick and Place": the cube goes to the tray, back to its start, and again
    to the tray (the objective loops), then cancelling ends the objective as cancelled."""
    assert near(cell.cube(), PICK_POSITION), f"the cube does not start at its pick pose: {cell.cube()}"
    handle = cell.client.start("3 Waypoints Pick and Place")
    try:
        # The cube must leave the table spot, rest in the tray, then rest at its start again.
        wait_for(lambda: near(cell.cube(), PLACE_POSITION), CYCLE_TIMEOUT_WALL, "the cube to reach the tray")
        assert not handle.done, handle.result(0)
        in_tray = _settled(cell, PLACE_POSITION)
        assert near(in_tray, PLACE_POSITION), f"cube in the tray at {in_tray}, expected {PLACE_POSITION}"
        wait_for(
            lambda: not near(cell.cube(), PLACE_POSITION), CYCLE_TIMEOUT_WALL, "the cube to leave the tray"
        )
        wait_for(lambda: near(cell.cube(), PICK_POSITION), CYCLE_TIMEOUT_WALL, "the cube to come back")
        back = _settled(cell, PICK_POSITION)
        assert near(back, PICK_POSITION), f"cube back at {back}, expected {PICK_POSITION}"
        # Still looping: the next cycle carries the cube to the tray again.
        wait_for(lambda: not near(cell.cube(), PICK_POSITION), CYCLE_TIMEOUT_WALL, "a second cycle to start")
        assert not handle.done, f"the objective stopped instead of looping: {handle.result(0)}"
    finally:
        cell.client.cancel()
    result = handle.result(30.0)
    assert result.cancelled, result


def _settled(cell: Cell, target: np.ndarray) -> np.ndarray:
    """The cube's position once it has stayed near ``target`` for a moment (the gripper let go)."""
    deadline = time.monotonic() + 30.0
    previous = cell.cube()
    while time.monotonic() < deadline:
        time.sleep(0.05)
        current = cell.cube()
        if np.linalg.norm(current - previous) < 1e-4:
            return current
        previous = current
    return previous


def run_and_expect_success(cell: Cell, name: str) -> None:
    """Run objective ``name`` to its end and check it succeeded."""
    result = cell.client.execute(name)
    assert result.succeeded, f"{name}: {result}"


def arm_at_waypoint(cell: Cell, waypoint: str, atol: float = 0.02) -> None:
    """The arm's joints are at saved waypoint ``waypoint`` (read back from /joint_states)."""
    from compat_cell import ARM, CONFIG

    from kinema.config import Workspace, resolve_config

    store_path = resolve_config(CONFIG, Workspace.discover(cell.workspace)).waypoints_path
    from kinema.config import WaypointStore

    saved = WaypointStore(store_path).get(waypoint)
    expected = dict(zip(saved.joint_names, saved.positions, strict=True))
    actual = joint_positions(cell)
    for joint in ARM:
        assert abs(actual[joint] - expected[joint]) < atol, (
            f"{joint}: {actual[joint]:.4f} != {expected[joint]:.4f}"
        )


def joint_positions(cell: Cell) -> dict[str, float]:
    """The latest ``/joint_states`` as joint name -> position."""
    message = wait_for(lambda: _joint_state(cell), 10.0, "a joint state")
    return dict(zip(message.name, message.position, strict=True))


def _joint_state(cell: Cell):
    box: list = []
    subscription = cell.node.create_subscription("sensor_msgs/msg/JointState", "/joint_states", box.append)
    try:
        wait_for(lambda: box, 10.0, "/joint_states")
        return box[-1]
    finally:
        subscription.close()
