"""MoveIt Pro's point-cloud objectives, unchanged, on Kinema's lab_sim headless: the snapshot lies on the
simulated table and objects, the wrist camera's picture comes with its intrinsics, and the octomap example
puts what the scene camera sees into the planning scene until the operator resumes.

They need OpenGL (EGL headless); without it they skip with the packages to install.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import numpy as np
import pytest
from lab_sim_library_cell import LibraryCell, wait_for

from kinema.perception.ros_messages import from_point_cloud2
from kinema.transport import from_dict

pytestmark = pytest.mark.slow

RUN_TIMEOUT = 240.0
CAPTURES = "/pcd_pointcloud_captures"


@pytest.fixture(scope="module")
def cell(library_cell: LibraryCell) -> LibraryCell:
    # Subscribed now, long before an objective sends to the UI: a subscription made just before a run
    # could still be on its way to the router when the snapshot went out.
    library_cell.listen("sensor_msgs/msg/PointCloud2", CAPTURES)
    # Each camera renders once before the objectives run (the corpus gives a message 10 s).
    cloud = "sensor_msgs/msg/PointCloud2"
    library_cell.render_each_camera_once(
        ((cloud, "/scene_camera/points"), (cloud, "/wrist_camera/points")), 120.0
    )
    return library_cell


def _world_T_body(cell: LibraryCell, body: str) -> np.ndarray:
    def read() -> np.ndarray:
        data = cell.driver.data
        transform = np.eye(4)
        transform[:3, :3] = data.body(body).xmat.reshape(3, 3)
        transform[:3, 3] = data.body(body).xpos
        return transform

    return cell.driver.simulation.call(read)


def _geometry_errors(
    cell: LibraryCell, origin: np.ndarray, points: np.ndarray
) -> tuple[np.ndarray, list[str]]:
    """For each point: |distance along the ray from ``origin`` to the first geom - distance to the point|,
    and the name of the geom the ray hits."""
    import mujoco

    model = cell.driver.model

    def cast() -> tuple[list[float], list[str]]:
        geom = np.array([-1], dtype=np.int32)
        errors, names = [], []
        for point in points:
            offset = point - origin
            distance = float(np.linalg.norm(offset))
            hit = mujoco.mj_ray(model, cell.driver.data, origin, offset / distance, None, 1, -1, geom)
            errors.append(abs(hit - distance) if hit >= 0 else np.inf)
            names.append(model.geom(int(geom[0])).name if hit >= 0 else "")
        return errors, names

    errors, names = cell.driver.simulation.call(cast)
    return np.array(errors), names


def settle(cell: LibraryCell) -> None:
    """Wait until the arm stands still (a snapshot of a moving arm cannot match the geometry of later)."""
    states = cell.listen("sensor_msgs/msg/JointState", "/joint_states")
    previous = None
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline:
        seen = len(states)
        wait_for(lambda seen=seen: len(states) > seen, 10.0, "a joint state")
        current = np.array(states[-1].position, dtype=float)
        if previous is not None and np.abs(current - previous).max() < 1e-5:
            return
        previous = current
        time.sleep(0.2)
    raise AssertionError("the arm kept moving for 30 s")


def test_take_snap_cloud_lies_on_the_table_and_the_objects(cell: LibraryCell) -> None:
    settle(cell)
    captures = cell.listen("sensor_msgs/msg/PointCloud2", CAPTURES)
    seen = len(captures)
    result = cell.client.execute("Take Scene Camera Snapshot", timeout=RUN_TIMEOUT)
    assert result.succeeded, result
    message = wait_for(lambda: captures[-1] if len(captures) > seen else None, 30.0, f"a cloud on {CAPTURES}")
    cloud = from_point_cloud2(message)
    assert cloud.frame_id == "scene_camera_optical_frame" and cloud.shape == (480, 640)
    world_T_camera = _world_T_body(cell, cloud.frame_id)
    world = cloud.finite().transformed(world_T_camera, "world")
    assert len(world) > 0.3 * len(cloud), f"only {len(world)} of {len(cloud)} pixels saw something"
    sample = world.points[np.random.default_rng(0).choice(len(world), size=400, replace=False)].astype(float)
    errors, names = _geometry_errors(cell, world_T_camera[:3, 3], sample)
    assert errors.max() < 0.01, (
        f"{np.sum(errors >= 0.01)} of 400 snapshot points are 1 cm or more off the MuJoCo geometry "
        f"(worst {errors.max():.4f} m on {names[int(np.argmax(errors))]!r})"
    )
    hit = set(names)
    assert "table" in hit, f"the snapshot's sampled points hit {sorted(hit)}, not the table"
    cube = cell.driver.simulation.call(lambda: cell.driver.data.body("cube").xpos.copy())
    on_cube = np.all(np.abs(world.points - cube) <= 0.028, axis=1)
    assert on_cube.sum() > 50, f"only {on_cube.sum()} snapshot points on the cube at {cube}"


def test_wrist_snap_and_the_wrist_camera_picture(cell: LibraryCell) -> None:
    captures = cell.listen("sensor_msgs/msg/PointCloud2", CAPTURES)
    seen = len(captures)
    result = cell.client.execute("Take Wrist Camera Snapshot", timeout=RUN_TIMEOUT)
    assert result.succeeded, result
    message = wait_for(lambda: captures[-1] if len(captures) > seen else None, 30.0, f"a cloud on {CAPTURES}")
    assert message.header.frame_id == "wrist_camera_optical_frame" and message.width == 640
    picture = cell.client.execute("Take Wrist Camera Image", timeout=RUN_TIMEOUT)
    assert picture.succeeded, picture


def test_octomap_example_adds_the_scene_to_the_planning_scene_until_resumed(cell: LibraryCell) -> None:
    scenes = cell.listen("moveit_msgs/msg/PlanningScene", "/monitored_planning_scene", latched=True)

    def octomap_boxes() -> int:
        if not scenes:
            return 0
        objects = {str(o.id): o for o in scenes[-1].world.collision_objects}
        return len(objects["octomap"].primitives) if "octomap" in objects else 0

    outcome: list[Any] = []
    runner = threading.Thread(
        target=lambda: outcome.append(cell.client.execute("Octomap Example", timeout=RUN_TIMEOUT)),
        daemon=True,
    )
    runner.start()
    boxes = wait_for(octomap_boxes, 120.0, "occupied cubes of the scene camera's cloud in the planning scene")
    assert boxes > 5, f"only {boxes} occupied cubes from the scene camera"
    resume = cell.node.create_publisher("std_msgs/msg/Empty", "/moveit_pro_breakpoint")
    deadline = time.monotonic() + 60.0
    while runner.is_alive() and time.monotonic() < deadline:
        resume.publish(from_dict("std_msgs/msg/Empty", {}))
        runner.join(0.2)
    assert outcome and outcome[0].succeeded, outcome
    # Its last step, Clear Snapshot, clears the octomap too, as MoveIt Pro's does.
    wait_for(lambda: octomap_boxes() == 0, 30.0, "the octomap to leave the planning scene")


def test_scan_scene_merges_three_wrist_views_into_one_thinned_cloud(cell: LibraryCell) -> None:
    captures = cell.listen("sensor_msgs/msg/PointCloud2", CAPTURES)
    seen = len(captures)
    result = cell.client.execute("Scan Scene - Multiple Point Clouds", timeout=RUN_TIMEOUT)
    assert result.succeeded, result
    merged = wait_for(lambda: captures[-1] if len(captures) > seen else None, 30.0, f"a cloud on {CAPTURES}")
    cloud = from_point_cloud2(merged)
    assert cloud.frame_id == "world" and cloud.colors is not None
    points = cloud.points.astype(float)
    cells = np.unique(np.floor(points / 0.01).astype(np.int64), axis=0)
    assert len(cells) == len(points) > 10000, f"{len(points)} points in {len(cells)} cells of 1 cm"
    span = np.ptp(points[:, :2], axis=0).max()
    # The views are 0.8 m to either side of the centre one: together they cover far more than one view.
    assert span > 1.5, f"the merged cloud spans only {span:.2f} m horizontally"


def _model_distances(cell: LibraryCell, cloud: Any, body: str, stl: str) -> np.ndarray:
    """Distance (m) of each point of ``cloud`` (world) to CAD model ``stl`` placed at MuJoCo's ``body``."""
    from scipy.spatial import cKDTree

    from kinema.perception import sample_mesh_surface
    from kinema.resources import bundled_dir

    model = sample_mesh_surface(
        bundled_dir("configs") / "lab_sim" / "description" / "assets" / stl, 50000, seed=0
    )
    on_body = model.transformed(_world_T_body(cell, body))
    distances, _ = cKDTree(on_body.points).query(cloud.finite().points)
    return distances


def test_register_cad_part_lays_the_microscope_model_onto_the_simulated_microscope(cell: LibraryCell) -> None:
    captures = cell.listen("sensor_msgs/msg/PointCloud2", CAPTURES)
    seen = len(captures)
    result = cell.client.execute("Register CAD Part", timeout=RUN_TIMEOUT)
    assert result.succeeded, result
    # It shows the model at the guess (red), the live cloud, then the registered model (green).
    sent = wait_for(lambda: captures[seen:] if len(captures) >= seen + 3 else None, 30.0, "three clouds")
    guess, aligned = from_point_cloud2(sent[0]), from_point_cloud2(sent[-1])
    assert (aligned.colors == [0, 255, 0]).all() and (guess.colors == [255, 0, 0]).all()
    before = np.median(_model_distances(cell, guess, "microscope", "microscope.stl"))
    after = np.median(_model_distances(cell, aligned, "microscope", "microscope.stl"))
    assert after < 0.008 < 0.05 < before, (
        f"median distance of the model cloud to the simulated microscope: {before * 1000:.0f} mm at the "
        f"guess, {after * 1000:.1f} mm after registration"
    )


def test_register_cad_part_subtree_finds_the_bottle_beside_its_guess(cell: LibraryCell) -> None:
    captures = cell.listen("sensor_msgs/msg/PointCloud2", CAPTURES)
    seen = len(captures)
    result = cell.client.execute("Register CAD Part Subtree", timeout=RUN_TIMEOUT)
    assert result.succeeded, result
    aligned = wait_for(
        lambda: (
            captures[-1]
            if len(captures) > seen and (from_point_cloud2(captures[-1]).colors == [0, 255, 0]).all()
            else None
        ),
        30.0,
        "the registered (green) bottle cloud",
    )
    after = np.median(_model_distances(cell, from_point_cloud2(aligned), "bottle_1", "bottle.stl"))
    assert after < 0.005, f"the registered bottle model is {after * 1000:.1f} mm (median) from bottle_1"


def test_grasp_planning_moves_the_gripper_to_its_first_candidate(cell: LibraryCell) -> None:
    from kinema.motion import RobotDescription, fk

    result = cell.client.execute("Grasp Planning", timeout=RUN_TIMEOUT)
    assert result.succeeded, result
    settle(cell)
    states = cell.listen("sensor_msgs/msg/JointState", "/joint_states")
    model = RobotDescription.lab_sim().load_model()
    latest = dict(zip(states[-1].name, states[-1].position, strict=True))
    q = np.array([latest.get(name, 0.0) for name in model.joint_names])
    grasp = fk(model, q, "grasp_link")
    assert np.linalg.norm(grasp[:3, 3] - [-0.04, 0.575, 0.58]) < 0.01, grasp[:3, 3]
    assert grasp[2, 2] < -0.98, f"the gripper does not point down: its z axis is {grasp[:3, 2]}"
