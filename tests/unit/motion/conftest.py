"""Fixtures for the motion tests: the bundled lab_sim robot, its planning scene and waypoints."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
import yaml

from kinema.motion import CollisionChecker, PlanningScene, RobotDescription, RobotModel
from kinema.resources import bundled_dir

WAYPOINTS = bundled_dir("configs") / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml"


@pytest.fixture(scope="session")
def description() -> RobotDescription:
    return RobotDescription.lab_sim()


@pytest.fixture(scope="session")
def model(description: RobotDescription) -> RobotModel:
    return description.load_model()


@pytest.fixture(scope="session")
def lab_scene(description: RobotDescription, model: RobotModel) -> PlanningScene:
    return description.load_scene(model)


@pytest.fixture
def checker(model: RobotModel, lab_scene: PlanningScene) -> CollisionChecker:
    """A checker with MoveIt Pro's default link padding (0.01 m), on a private copy of the scene."""
    scene = PlanningScene(dict(lab_scene.objects))
    return CollisionChecker(model, scene, padding=0.01)


@pytest.fixture(scope="session")
def waypoints() -> dict[str, dict[str, float]]:
    entries = yaml.safe_load(WAYPOINTS.read_text())
    return {
        e["name"]: dict(zip(e["joint_state"]["name"], e["joint_state"]["position"], strict=True))
        for e in entries
    }


@pytest.fixture(scope="session")
def waypoint_q(model: RobotModel, waypoints: dict[str, dict[str, float]]) -> Callable[[str], np.ndarray]:
    """Full configuration of a waypoint by name."""
    return lambda name: model.configuration(waypoints[name])


@pytest.fixture(scope="session")
def arm_goal(model: RobotModel, waypoints: dict[str, dict[str, float]]) -> Callable[[str], dict[str, float]]:
    """The ``manipulator`` joints of a waypoint, as RetrieveWaypoint would hand them to the planner."""
    joints = model.group("manipulator").joint_names
    return lambda name: {k: v for k, v in waypoints[name].items() if k in joints}
