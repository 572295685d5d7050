"""lab_sim's waypoints: every one MoveIt Pro's lab_sim objectives name is there, reachable without collision,
and the ones about a place put the gripper where MoveIt Pro's put MoveIt Pro's (the flasks' necks, above
the burners)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from kinema.motion import CollisionChecker, fk
from kinema.resources import bundled_dir

LAB_SIM = bundled_dir("configs") / "lab_sim"
CORPUS = Path(__file__).resolve().parents[3].parent / "shared" / "compat" / "moveit_pro" / "lab_sim"

# The waypoints MoveIt Pro's lab_sim objectives name (the files' waypoint_name, pick and place values).
NAMED_BY_MOVEIT_PRO = {
    "3 Waypoint Mid Point",
    "3 Waypoint Pick Pose",
    "3 Waypoint Place Pose",
    "Above Pick Object",
    "Flask 1 - Pick",
    "Flask 1 - Place",
    "Flask 2 - Pick",
    "Flask 2 - Place",
    "Home",
    "Look at Base",
    "Look at Bottles Left",
    "Look at Flasks",
    "Look at Microscope",
    "Look at Table",
    "Look at Tray",
    "MPC Pose Tracking",
    "Pose Tracking",
    "VFC Start",
    "Workspace Right",
    "Wrist 2 Max",
    "Wrist 2 Min",
}

# grasp_link's position (m) and z axis in MoveIt Pro's lab_sim at its waypoints' joint values (its URDF).
MOVEIT_PRO_GRASP = {
    "Above Pick Object": ((0.0096, 0.7454, 0.6982), (-0.003, -0.033, -0.999)),
    "Flask 1 - Pick": ((-0.3571, 0.4002, 0.56), (-0.002, 0.198, -0.98)),
    "Flask 2 - Pick": ((-0.5017, 0.4735, 0.5758), (-0.002, 0.199, -0.98)),
    "Flask 1 - Place": ((0.5549, 0.5603, 0.6462), (-0.003, 0.191, -0.982)),
    "Flask 2 - Place": ((0.6599, 0.56, 0.6508), (-0.004, 0.188, -0.982)),
    "Pose Tracking": ((-0.0455, 0.5965, 0.7061), (-0.001, -0.027, -1.0)),
    "Look at Flasks": ((-0.2977, 0.4403, 0.7543), (-0.076, 0.46, -0.885)),
    "Look at Bottles Left": ((0.0135, 0.3578, 0.6564), (0.745, 0.213, -0.632)),
}


@pytest.fixture(scope="module")
def waypoints(description) -> dict[str, np.ndarray]:
    """Waypoint name -> the model's configuration (joints it does not name at 0)."""
    model = description.load_model()
    entries = yaml.safe_load((LAB_SIM / "waypoints" / "lab_sim_waypoints.yaml").read_text())
    found = {}
    for entry in entries:
        state = dict(zip(entry["joint_state"]["name"], entry["joint_state"]["position"], strict=True))
        found[entry["name"]] = np.array([state.get(j, 0.0) for j in model.joint_names])
    return found


@pytest.fixture(scope="module")
def checker(description) -> CollisionChecker:
    model = description.load_model()
    return CollisionChecker(model, description.load_scene(model))


def test_every_waypoint_moveit_pros_objectives_name_is_there(waypoints) -> None:
    names = set(NAMED_BY_MOVEIT_PRO)
    if CORPUS.is_dir():
        import re

        for path in (CORPUS / "objectives").glob("*.xml"):
            text = path.read_text()
            names |= set(re.findall(r'(?:waypoint_name|pick|place)="([^"{]+)"', text))
    assert not sorted(names - set(waypoints)), sorted(names - set(waypoints))


def test_waypoints_are_collision_free(waypoints, checker) -> None:
    colliding = {name: checker.colliding_pairs(q) for name, q in waypoints.items() if checker.in_collision(q)}
    assert not colliding, colliding


@pytest.mark.parametrize("name", sorted(MOVEIT_PRO_GRASP))
def test_waypoints_about_a_place_put_the_gripper_where_moveit_pro_does(name, waypoints, description) -> None:
    position, axis = MOVEIT_PRO_GRASP[name]
    pose = fk(description.load_model(), waypoints[name], "grasp_link")
    assert pose[:3, 3] == pytest.approx(position, abs=1e-3)
    assert pose[:3, 2] == pytest.approx(axis, abs=5e-3)


def test_wrist_2_max_and_min_differ_only_in_wrist_2_at_its_limits(waypoints, checker, description) -> None:
    """Joint Diagnostic cycles wrist_2 between them: every configuration on the way is collision-free."""
    model = description.load_model()
    high, low = waypoints["Wrist 2 Max"], waypoints["Wrist 2 Min"]
    wrist_2 = model.joint_names.index("wrist_2_joint")
    moved = [model.joint_names[i] for i in np.flatnonzero(np.abs(high - low) > 1e-9)]
    assert moved == ["wrist_2_joint"], moved
    assert high[wrist_2] == pytest.approx(3.14) and low[wrist_2] == pytest.approx(-3.14)
    for t in np.linspace(0.0, 1.0, 200):
        assert not checker.in_collision(low + t * (high - low)), (
            f"collision at wrist_2 = {low[wrist_2] + t * 6.28}"
        )


@pytest.mark.parametrize("number", [1, 2])
def test_flask_waypoints_hold_the_neck_and_stand_it_above_its_burner(
    number, waypoints, cell, description
) -> None:
    """Pick: grasp_link on the flask's neck axis, within the neck's height, the fingers closing across it
    (along world x, as MoveIt Pro's). Place: the flask held as picked stands above its burner."""
    model = description.load_model()
    flask = cell.body_pos(f"flask_{number}")
    burner = cell.body_pos(f"burner_{number}")
    pick = fk(model, waypoints[f"Flask {number} - Pick"], "grasp_link")
    assert np.linalg.norm(pick[:2, 3] - flask[:2]) < 2e-3
    neck = cell.m.geom(f"flask_{number}_neck")
    neck_low = flask[2] + neck.pos[2] - neck.size[1]
    neck_top = flask[2] + neck.pos[2] + neck.size[1]
    assert neck_low + 0.02 < pick[2, 3] < neck_top - 0.015, (neck_low, pick[2, 3], neck_top)
    assert abs(pick[0, 1]) > 0.99, f"the fingers close along {pick[:3, 1]}, not across the flask's tilt"
    place = fk(model, waypoints[f"Flask {number} - Place"], "grasp_link")
    assert np.linalg.norm(place[:2, 3] - burner[:2]) < 2e-3
    height_held = pick[2, 3] - flask[2]
    burner_top = burner[2] + 2 * cell.m.geom(f"burner_{number}").size[1]
    assert 0.0 < place[2, 3] - height_held - burner_top < 0.03
