"""lab_sim's cameras through the driver: clouds on the simulated geometry, intrinsics that match the
render, and no rendering while nobody subscribes.

These need OpenGL (EGL headless); without it they skip with the packages to install.
"""

from __future__ import annotations

import queue
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from driver_harness import Sim, wait_for

from kinema.drivers.mujoco import names as n
from kinema.drivers.mujoco.cameras import GL_HELP, SimState
from kinema.perception.ros_messages import from_point_cloud2, image_array, intrinsics_of

CAMERAS = ("scene_camera", "wrist_camera")


@pytest.fixture
def camera_sim(start_sim: Callable[..., Sim]) -> Sim:
    sim = start_sim()
    cameras = sim.driver.cameras
    assert cameras is not None, "lab_sim has cameras, the driver serves none"
    assert cameras.ready.wait(60), "the camera thread did not get ready within 60 s"
    if cameras.unavailable is not None:
        pytest.skip(f"no OpenGL for MuJoCo ({cameras.unavailable}). {GL_HELP}")
    return sim


def _receive(sim: Sim, camera: str, stream: str, timeout: float = 30.0) -> Any:
    """Subscribe to ``/<camera>/<stream>``, return the first message, unsubscribe."""
    received: queue.Queue[Any] = queue.Queue()
    subscription = sim.node.create_subscription(
        n.CAMERA_STREAMS[stream], n.camera_topic(camera, stream), received.put
    )
    try:
        return received.get(timeout=timeout)
    except queue.Empty:
        raise AssertionError(f"no message on {n.camera_topic(camera, stream)} within {timeout} s") from None
    finally:
        subscription.close()


def _world_T_body(sim: Sim, body: str) -> np.ndarray:
    def read() -> np.ndarray:
        data = sim.driver.data
        transform = np.eye(4)
        transform[:3, :3] = data.body(body).xmat.reshape(3, 3)
        transform[:3, 3] = data.body(body).xpos
        return transform

    return sim.driver.simulation.call(read)


def _ray_distance(sim: Sim, origin: np.ndarray, direction: np.ndarray) -> float:
    """Distance from ``origin`` along unit ``direction`` to the first MuJoCo geom (inf: none)."""
    import mujoco

    model = sim.driver.model
    geom = np.array([-1], dtype=np.int32)

    def cast() -> float:
        return mujoco.mj_ray(model, sim.driver.data, origin, direction, None, 1, -1, geom)

    distance = sim.driver.simulation.call(cast)
    return float("inf") if distance < 0 else float(distance)


@pytest.mark.parametrize("camera", CAMERAS)
def test_cloud_points_lie_on_the_simulated_geometry(camera_sim: Sim, camera: str) -> None:
    """Sampled points of /<camera>/points are within 1 cm of the surface a ray through them hits."""
    cloud = from_point_cloud2(_receive(camera_sim, camera, "points"))
    assert cloud.frame_id == f"{camera}_optical_frame"
    assert cloud.shape == (480, 640), f"the cloud is not organised 640x480: {cloud.shape}"
    assert cloud.colors is not None
    finite = cloud.finite()
    assert len(finite) > 0.3 * len(cloud), f"only {len(finite)} of {len(cloud)} pixels saw something"
    world_T_camera = _world_T_body(camera_sim, cloud.frame_id)
    world = finite.transformed(world_T_camera, "world")
    origin = world_T_camera[:3, 3]
    rng = np.random.default_rng(0)
    errors = []
    for index in rng.choice(len(world), size=300, replace=False):
        point = world.points[index].astype(float)
        offset = point - origin
        distance = float(np.linalg.norm(offset))
        hit = _ray_distance(camera_sim, origin, offset / distance)
        errors.append(abs(hit - distance))
    errors_array = np.array(errors)
    assert errors_array.max() < 0.01, (
        f"{camera}: {np.sum(errors_array >= 0.01)} of 300 points are 1 cm or more off the geometry "
        f"(worst {errors_array.max():.4f} m, median {np.median(errors_array):.4f} m)"
    )


def test_scene_camera_sees_the_table_and_the_cube_where_they_are(camera_sim: Sim) -> None:
    cloud = from_point_cloud2(_receive(camera_sim, "scene_camera", "points"))
    world = cloud.finite().transformed(_world_T_body(camera_sim, cloud.frame_id), "world")
    cube = camera_sim.driver.simulation.call(lambda: camera_sim.driver.data.body("cube").xpos.copy())
    points = world.points.astype(float)
    on_cube = np.all(np.abs(points - cube) <= 0.025 + 0.003, axis=1)
    assert on_cube.sum() > 50, f"only {on_cube.sum()} cloud points on the cube at {cube}"
    top = points[on_cube & (points[:, 2] > cube[2] + 0.02)]
    assert len(top) > 20 and abs(np.median(top[:, 2]) - (cube[2] + 0.025)) < 0.005, (
        f"cube top face expected at z={cube[2] + 0.025:.3f}, points there: {len(top)}, "
        f"median z {np.median(top[:, 2]) if len(top) else float('nan'):.4f}"
    )
    red = world.colors[on_cube]
    assert np.median(red[:, 0]) > 2 * np.median(red[:, 1]), f"the cube's points are not red: {red[:5]}"
    table = points[(points[:, 1] > 0.4) & (points[:, 1] < 1.0) & (np.abs(points[:, 2] - 0.474) < 0.01)]
    assert len(table) > 10000, f"only {len(table)} points on the table top"


@pytest.mark.parametrize("camera", CAMERAS)
def test_camera_info_matches_the_render(camera_sim: Sim, camera: str) -> None:
    """Rays through pixels back-projected with the served K hit the scene at the depth image.s depth."""
    info = _receive(camera_sim, camera, "camera_info")
    intrinsics = intrinsics_of(info)
    assert (intrinsics.width, intrinsics.height) == (640, 480)
    assert info.header.frame_id == f"{camera}_optical_frame"
    depth_message = _receive(camera_sim, camera, "depth")
    assert depth_message.encoding == "32FC1"
    depth = image_array(depth_message)
    color = image_array(_receive(camera_sim, camera, "color"))
    assert color.shape == (480, 640, 3) and depth.shape == (480, 640)
    camera_T_world = np.linalg.inv(_world_T_body(camera_sim, info.header.frame_id))
    # Points on the pixel grid, back-projected with the served intrinsics and cast into the scene.
    world_T_camera = np.linalg.inv(camera_T_world)
    checked = 0
    for u, v in [(100, 100), (320, 240), (540, 380), (200, 400), (600, 50)]:
        ray = np.array([(u - intrinsics.cx) / intrinsics.fx, (v - intrinsics.cy) / intrinsics.fy, 1.0])
        direction = world_T_camera[:3, :3] @ (ray / np.linalg.norm(ray))
        hit = _ray_distance(camera_sim, world_T_camera[:3, 3], direction)
        if not np.isfinite(hit) or not np.isfinite(depth[v, u]):
            continue
        expected_z = hit / np.linalg.norm(ray)
        assert abs(depth[v, u] - expected_z) < 0.01 * max(1.0, expected_z), (
            f"{camera} pixel ({u}, {v}): depth image {depth[v, u]:.4f} m, "
            f"the ray through K hits at z={expected_z:.4f} m"
        )
        checked += 1
    assert checked >= 3, f"only {checked} of 5 pixels saw something"


def test_nothing_is_rendered_while_nobody_subscribes(camera_sim: Sim) -> None:
    cameras = camera_sim.driver.cameras
    assert cameras is not None
    start = camera_sim.driver.sim_time
    wait_for(lambda: camera_sim.driver.sim_time > start + 2.0, 30, "2 s of sim time")
    assert cameras.frames_rendered == 0, "frames were rendered with no subscriber"
    _receive(camera_sim, "wrist_camera", "color")
    rendered = cameras.frames_rendered
    assert rendered >= 1
    # The subscription is gone: rendering stops (a frame may have been in flight).
    wait_for(lambda: _stable(cameras), 60, "rendering to stop")
    settled = cameras.frames_rendered
    later = camera_sim.driver.sim_time
    wait_for(lambda: camera_sim.driver.sim_time > later + 2.0, 30, "2 s more of sim time")
    assert cameras.frames_rendered == settled, "frames were still rendered after the subscriber left"


def _stable(cameras: Any) -> bool:
    import time

    # 2 s: a software-rendered frame that was in flight can take over a second on a busy machine.
    before = cameras.frames_rendered
    time.sleep(2.0)
    return cameras.frames_rendered == before


def test_cloud_is_stamped_with_sim_time(camera_sim: Sim) -> None:
    message = _receive(camera_sim, "scene_camera", "points")
    stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
    now = camera_sim.driver.simulation.call(lambda: SimState.of(camera_sim.driver.data).time)
    assert 0.0 < stamp <= now


def test_without_opengl_the_driver_runs_on_and_says_cameras_are_unavailable(
    start_sim: Callable[..., Sim], monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """No OpenGL context (simulated): the physics still runs, the log names the packages to install and
    the camera topics are withdrawn rather than left silent."""
    from kinema.drivers.mujoco import cameras as cameras_module

    def no_gl(_model: Any) -> Any:
        raise RuntimeError("Cannot initialize a EGL device display")

    monkeypatch.setattr(cameras_module, "CameraRenderer", no_gl)
    with caplog.at_level("WARNING", logger="kinema.drivers.mujoco.cameras"):
        sim = start_sim()
        cameras = sim.driver.cameras
        assert cameras is not None and cameras.ready.wait(30)
    assert cameras.unavailable is not None and "EGL" in cameras.unavailable
    assert "apt-get install -y libegl1" in caplog.text, caplog.text
    start = sim.driver.sim_time
    wait_for(lambda: sim.driver.sim_time > start + 1.0, 30, "the simulation to keep running")
    served = {i.name for i in sim.driver.interfaces()}
    assert n.JOINT_STATES_TOPIC in served and "/scene_camera/points" not in served
    wait_for(
        lambda: not sim.node.graph().publishers("/scene_camera/points"),
        10,
        "the camera topics to be withdrawn",
    )


def test_a_driver_process_without_opengl_simulates_and_logs_what_to_install(router_endpoint: str) -> None:
    """``MUJOCO_GL=disable`` is what Kinema sets when libEGL cannot be loaded (``import mujoco`` would fail
    with egl): the driver process still serves /clock and its log names the packages."""
    import os
    import select
    import subprocess

    from kinema.drivers import driver_spec
    from kinema.transport import Node, open_session

    read_fd, write_fd = os.pipe()
    argv = driver_spec("mujoco").command(
        config="lab_sim", connect=router_endpoint, sim_speed="max", ready_fd=write_fd
    )
    env = {**os.environ, "MUJOCO_GL": "disable"}
    process = subprocess.Popen(argv, pass_fds=(write_fd,), stderr=subprocess.PIPE, env=env)
    os.close(write_fd)
    try:
        ready = select.select([read_fd], [], [], 60.0)[0]
        assert ready, "the driver did not report ready within 60 s"
        with open_session(router_endpoint) as session:
            node = Node(session, "test_client")
            clock: list[float] = []
            node.create_subscription(
                n.CLOCK_TYPE, n.CLOCK_TOPIC, lambda m: clock.append(m.clock.sec + m.clock.nanosec * 1e-9)
            )
            wait_for(lambda: len(clock) > 10 and clock[-1] > clock[0], 30, "/clock from the driver process")
    finally:
        os.close(read_fd)
        process.terminate()
        _, stderr = process.communicate(timeout=20)
    log = stderr.decode()
    assert "cameras unavailable" in log and "apt-get install -y libegl1" in log, log
    assert "Traceback" not in log, log


@pytest.mark.parametrize("camera", CAMERAS)
def test_the_planning_frame_tree_knows_each_camera_frame_where_the_simulator_has_it(
    camera_sim: Sim, camera: str
) -> None:
    """The clouds' frame is a link of the URDF, so frame lookups (TransformPoseFrame, TF) can resolve it."""
    from kinema.motion import RobotDescription, frame_poses

    model = RobotDescription.lab_sim().load_model()
    positions = camera_sim.driver.simulation.call(
        lambda: {
            name: float(camera_sim.driver.data.joint(name).qpos[0])
            for name in model.joint_names
            if name in camera_sim.driver.index.joint_names
        }
    )
    q = np.array([positions.get(name, 0.0) for name in model.joint_names])
    frame = f"{camera}_optical_frame"
    planned = frame_poses(model, q)[frame]
    simulated = _world_T_body(camera_sim, frame)
    np.testing.assert_allclose(planned, simulated, atol=1e-4, err_msg=f"{frame}: URDF vs MuJoCo")
