"""MoveIt Pro's lab_sim objective files, byte for byte, run on Kinema's lab_sim (headless, max sim speed)."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest
from compat_cell import Cell
from objective_checks import (
    MOVEIT_PRO_OBJECTIVES,
    arm_at_waypoint,
    joint_positions,
    run_and_expect_success,
    run_pick_and_place_two_placements,
)

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def cell(start_cell, compat_objectives: Path) -> Cell:
    return start_cell(objectives=compat_objectives)


def test_the_copied_files_are_the_originals(compat_objectives: Path, shared_dir_module: Path) -> None:
    originals = shared_dir_module / "compat" / "moveit_pro" / "objectives"
    names = sorted(p.name for p in originals.glob("*.xml"))
    assert names == sorted(p.name for p in compat_objectives.glob("*.xml"))
    for name in names:
        digest = hashlib.sha256((originals / name).read_bytes()).hexdigest()
        assert hashlib.sha256((compat_objectives / name).read_bytes()).hexdigest() == digest, name


def test_the_library_lists_moveit_pros_objectives(cell: Cell) -> None:
    names = {info.name for info in cell.client.objectives()}
    for expected in MOVEIT_PRO_OBJECTIVES:
        assert expected in names


def test_close_and_open_gripper_succeed(cell: Cell) -> None:
    run_and_expect_success(cell, "Close Gripper")
    run_and_expect_success(cell, "Open Gripper")


def test_look_at_table_moves_the_arm_to_its_waypoint(cell: Cell) -> None:
    run_and_expect_success(cell, "Look at Table")
    arm_at_waypoint(cell, "Look at Table")


def test_reset_mujoco_robot_puts_the_arm_upright_and_controllers_back(cell: Cell) -> None:
    run_and_expect_success(cell, "Reset MuJoCo Robot")
    state = joint_positions(cell)
    assert abs(state["shoulder_lift_joint"] + 1.57) < 0.02
    assert abs(state["elbow_joint"]) < 0.02
    # The controllers it switched off are on again: a motion right after works.
    run_and_expect_success(cell, "Look at Table")


def test_pick_and_place_moves_the_cube_to_the_tray_and_back_and_loops(cell: Cell) -> None:
    run_pick_and_place_two_placements(cell)
