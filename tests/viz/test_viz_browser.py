"""The 3D view in a real (headless) Chromium: the robot is drawn, moves while a trajectory runs, the planned
path shows, and the page says so when the runtime goes away and recovers when it returns.

Needs Debian's ``chromium`` (``apt-get install -y chromium``); skipped with that hint when it is missing.
"""

from __future__ import annotations

import io
import json
import os
import socket
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from headless_chromium import HeadlessChromium, find_chromium

pytestmark = pytest.mark.slow

CHROMIUM = find_chromium()
if CHROMIUM is None:
    pytest.skip(
        "chromium is not installed (apt-get install -y chromium): kinema view's browser tests are skipped",
        allow_module_level=True,
    )

ARM = (
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
HOME = np.array([0.0, 0.0, -2.0, 2.0, -1.5708, -1.5708, 0.0])
# Pixels whose color changes by more than this (0-255, any channel) count as changed.
PIXEL_DELTA = 30


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def _pixels(png: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int16)


def _keep(name: str, png: bytes) -> None:
    """Save a screenshot under $KINEMA_VIZ_SHOTS (to look at what the test saw)."""
    folder = os.environ.get("KINEMA_VIZ_SHOTS")
    if folder:
        Path(folder).mkdir(parents=True, exist_ok=True)
        (Path(folder) / f"{name}.png").write_bytes(png)


def _wait_sim_time(runtime: Runtime, seconds: float, timeout: float = 60.0) -> None:
    """Wait until the simulation has run ``seconds`` more (the arm moves on by that much)."""
    until = runtime.driver.sim_time + seconds
    deadline = time.monotonic() + timeout
    while runtime.driver.sim_time < until:
        assert time.monotonic() < deadline, f"the simulation did not run {seconds} s within {timeout} s"
        time.sleep(0.02)


def _changed(a: bytes, b: bytes) -> np.ndarray:
    return np.abs(_pixels(a) - _pixels(b)).max(axis=2) > PIXEL_DELTA


def _trajectory(goal: np.ndarray, duration: float, points: int = 31, legs: int = 1) -> dict[str, Any]:
    """HOME to ``goal`` in ``duration`` s (minimum jerk); with ``legs`` > 1, back and forth that often."""
    rows = []
    for t in np.linspace(0.0, duration * legs, points * legs - (legs - 1)):
        leg, within = divmod(t, duration) if t < duration * legs else (legs - 1, duration)
        s = within / duration if int(leg) % 2 == 0 else 1.0 - within / duration
        shape = 10 * s**3 - 15 * s**4 + 6 * s**5
        nanoseconds = round(t * 1e9)
        rows.append(
            {
                "positions": (HOME + (goal - HOME) * shape).tolist(),
                "time_from_start": {"sec": nanoseconds // 10**9, "nanosec": nanoseconds % 10**9},
            }
        )
    return {"trajectory": {"joint_names": list(ARM), "points": rows}}


class Runtime:
    """A router and the lab_sim driver in this process (real time), restartable."""

    def __init__(self) -> None:
        from kinema.transport import free_endpoint, host_router

        self.endpoint = free_endpoint()
        self.router = host_router(self.endpoint)
        self.driver: Any = None
        self.start_driver()

    def start_driver(self) -> None:
        from kinema.drivers.mujoco import MujocoDriver, MujocoDriverSettings

        self.driver = MujocoDriver(self.router, MujocoDriverSettings.from_config("lab_sim"))
        self.driver.start()

    def stop_driver(self) -> None:
        if self.driver is not None:
            self.driver.stop()
            self.driver = None

    def close(self) -> None:
        self.stop_driver()
        self.router.close()


@pytest.fixture(scope="module")
def runtime() -> Iterator[Runtime]:
    started = Runtime()
    yield started
    started.close()


@pytest.fixture(scope="module")
def viewer(runtime: Runtime) -> Iterator[Any]:
    from kinema.viz.view import ViewerOptions, start_viewer

    started = start_viewer(
        ViewerOptions(endpoint=runtime.endpoint, config="lab_sim", port=_free_port(), open_browser=False)
    )
    yield started
    started.close()


@pytest.fixture(scope="module")
def page(viewer: Any) -> Iterator[HeadlessChromium]:
    assert CHROMIUM is not None
    with HeadlessChromium(CHROMIUM, width=900, height=700) as browser:
        browser.navigate(viewer.url)
        browser.wait_for(
            "typeof viewer !== 'undefined' && kinema.framed && viewer.num_messages_received > 30", timeout=60
        )
        # The info line shows the sim time, which changes every frame: keep it out of the pixels compared.
        browser.evaluate("document.getElementById('kinema-info').style.visibility = 'hidden'")
        yield browser


def _drawn(path: list[str]) -> str:
    """JavaScript: is there a meshcat object at ``path``? (Walks the tree; ``find`` would create nodes.)"""
    return (
        "(function(p){let n=viewer.scene_tree;for(const k of p){n=n.children[k];if(!n)return false;}"
        f"return '<object>' in n.children;}})({json.dumps(path)})"
    )


def _hidden(paths: list[str]) -> str:
    """JavaScript: is every meshcat object at ``paths`` (scene paths) there and invisible?"""
    return (
        "(function(ps){for(const p of ps){let n=viewer.scene_tree;"
        "for(const k of p.split('/').filter(Boolean)){n=n.children[k];if(!n)return false;}"
        f"if(!n.object||n.object.visible!==false)return false;}}return true;}})({json.dumps(paths)})"
    )


def _settled_screenshot(page: HeadlessChromium, ready: str | None = None) -> bytes:
    """A screenshot once ``ready`` (JavaScript) holds and a frame has been drawn since."""
    if ready is not None:
        page.wait_for(ready, timeout=30.0)
    page.evaluate(
        "window.__kinema_drawn=false;viewer.set_dirty();"
        "requestAnimationFrame(()=>requestAnimationFrame(()=>{window.__kinema_drawn=true;}))"
    )
    page.wait_for("window.__kinema_drawn", timeout=30.0)
    return page.screenshot()


def test_the_page_is_served_from_loopback_without_network_resources(viewer: Any) -> None:
    import urllib.request

    assert viewer.url.startswith("http://127.0.0.1:")
    with urllib.request.urlopen(viewer.url, timeout=10) as answer:
        html = answer.read().decode()
    assert 'src="main.min.js"' in html and "http" not in html.split("<script", 1)[1].split(">", 1)[0]


def test_the_robot_is_drawn(viewer: Any, page: HeadlessChromium) -> None:
    from kinema.viz import scene_commands as sc

    robot = [
        node for node in viewer.bridge.scene.bodies if not node.static and node.name not in ("cube", "tray")
    ]
    assert len(robot) >= 8
    with_robot = _settled_screenshot(page)
    viewer.server.send([sc.set_property(node.path, "visible", False) for node in robot])
    try:
        without_robot = _settled_screenshot(page, _hidden([node.path for node in robot]))
    finally:
        viewer.server.send([sc.set_property(node.path, "visible", True) for node in robot])
    _keep("with_robot", with_robot)
    _keep("without_robot", without_robot)
    changed = _changed(with_robot, without_robot)
    assert changed.sum() > 2000, "hiding the robot changed too few pixels: the robot is not drawn"


def test_the_arm_moves_while_a_trajectory_executes(
    runtime: Runtime, viewer: Any, page: HeadlessChromium
) -> None:
    from kinema.drivers.mujoco import names
    from kinema.transport import Node

    node = Node(runtime.router, "viz_test_client")
    try:
        client = node.create_action_client(
            names.FOLLOW_JOINT_TRAJECTORY_TYPE, names.FOLLOW_JOINT_TRAJECTORY_ACTION
        )
        goal = HOME + np.array([0.0, 1.4, 0.5, -0.6, 0.0, 0.0, 0.0])
        # Back and forth for 32 s, so that two screenshots fit inside it on a busy machine (each can
        # take seconds) while the arm keeps moving; cancelled once they are taken.
        moving = _trajectory(goal, 8.0, legs=4)
        handle = client.send_goal(moving, timeout=10.0)
        assert handle.accepted
        _wait_sim_time(runtime, 1.5)
        first = page.screenshot()
        _wait_sim_time(runtime, 2.0)
        second = page.screenshot()
        assert not handle.done(), "the trajectory ended before both screenshots were taken"
        _keep("moving_1", first)
        _keep("moving_2", second)
        changed = _changed(first, second)
        assert changed.sum() > 1000, "the arm's pixels did not move between two screenshots"
        handle.cancel()
    finally:
        node.close()


def test_a_planned_trajectory_is_drawn_as_the_tool_path(runtime: Runtime, page: HeadlessChromium) -> None:
    from kinema.transport import Node, from_dict
    from kinema.ui_topics import PLANNED_TRAJECTORY_TOPIC, PLANNED_TRAJECTORY_TYPE

    node = Node(runtime.router, "viz_test_planner")
    try:
        publisher = node.create_publisher(PLANNED_TRAJECTORY_TYPE, PLANNED_TRAJECTORY_TOPIC)
        message = from_dict(PLANNED_TRAJECTORY_TYPE, _trajectory(HOME + 0.3, 2.0)["trajectory"])
        deadline = time.monotonic() + 20
        drawn = None
        while time.monotonic() < deadline and not drawn:
            publisher.publish(message)  # until the viewer's subscription has matched
            time.sleep(0.3)
            drawn = page.evaluate(_drawn(["kinema", "planned_path", "line"]))
        assert drawn, "the planned tool path did not appear in the page"
        _keep("planned_path", _settled_screenshot(page))
    finally:
        node.close()


def test_a_visualize_pose_triad_appears_and_expires_after_its_lifetime(
    runtime: Runtime, page: HeadlessChromium
) -> None:
    from kinema.transport import Node, from_dict
    from kinema.ui_topics import MARKER_ARRAY_TOPIC, MARKER_ARRAY_TYPE

    triad = []
    for axis in range(3):
        tip = {"x": 0.6, "y": 0.0, "z": 1.0}
        tip["xyz"[axis]] += 0.1
        triad.append(
            {
                "header": {"frame_id": "world"},
                "ns": "goal_pose",
                "id": axis,
                "type": 0,
                "pose": {"orientation": {"w": 1.0}},
                "scale": {"x": 0.008, "y": 0.015, "z": 0.02},
                "color": {"r": float(axis == 0), "g": float(axis == 1), "b": float(axis == 2), "a": 1.0},
                "lifetime": {"sec": 3, "nanosec": 0},
                "points": [{"x": 0.6, "y": 0.0, "z": 1.0}, tip],
            }
        )
    shown = _drawn(["kinema", "markers", "goal_pose", "2", "head"])
    gone = f"!{shown}"
    node = Node(runtime.router, "viz_test_markers")
    try:
        publisher = node.create_publisher(MARKER_ARRAY_TYPE, MARKER_ARRAY_TOPIC)
        message = from_dict(MARKER_ARRAY_TYPE, {"markers": triad})
        deadline = time.monotonic() + 20
        sent = time.monotonic()
        while time.monotonic() < deadline and not page.evaluate(shown):
            sent = time.monotonic()  # the lifetime runs from a publish at or before this one
            publisher.publish(message)
            time.sleep(0.3)
        assert page.evaluate(shown), "the triad did not appear in the page"
        _keep("marker", _settled_screenshot(page))
        page.wait_for(gone, timeout=20)
        lasted = time.monotonic() - sent
        assert lasted > 1.5, f"the triad went away {lasted:.1f} s after the last publish, not after its 3 s"
    finally:
        node.close()


def test_the_page_says_when_the_runtime_goes_away_and_recovers(
    runtime: Runtime, page: HeadlessChromium
) -> None:
    banner = "document.getElementById('kinema-banner')"
    assert page.evaluate(f"{banner}.textContent") == ""
    runtime.stop_driver()
    text = page.wait_for(f"{banner}.className === 'error' && {banner}.textContent", timeout=15)
    assert "not reachable" in text
    _keep("runtime_lost", page.screenshot())
    runtime.start_driver()
    page.wait_for(f"{banner}.textContent === ''", timeout=20)


def _three(path: list[str]) -> str:
    """JavaScript: the three.js object meshcat holds at ``path`` (null when none)."""
    return (
        "(function(p){let n=viewer.scene_tree;for(const k of p){n=n.children[k];if(!n)return null;}"
        f"const o=n.children['<object>'];return o?o.object:null;}})({json.dumps(path)})"
    )


def test_a_point_cloud_snapshot_is_drawn_coloured_and_decimated_and_cleared(
    runtime: Runtime, page: HeadlessChromium
) -> None:
    """SendPointCloudToUI draws the cloud in its own colours, at most MAX_DRAWN_POINTS of it; ClearSnapshot
    removes it."""
    from kinema.behaviors import BehaviorContext
    from kinema.bt import NodeStatus
    from kinema.interfaces import load_interfaces
    from kinema.perception import PointCloud
    from kinema.perception.ros_messages import to_point_cloud2
    from kinema.plugins import BehaviorHost
    from kinema.testing import tick_behavior
    from kinema.transport import Node

    host = BehaviorHost(["kinema::CoreBehaviorsLoader"])
    host.load().raise_for_errors()
    ticks = 240  # a 0.4 m square of 240 x 240 = 57,600 points at z = 1 m: left half red, right half green
    u, v = np.meshgrid(np.linspace(-0.2, 0.2, ticks), np.linspace(-0.2, 0.2, ticks))
    points = np.stack([0.6 + u.ravel(), v.ravel(), np.full(u.size, 1.0)], axis=1).astype(np.float32)
    colors = np.where((v.ravel() < 0)[:, None], [230, 20, 20], [20, 200, 20]).astype(np.uint8)
    cloud = to_point_cloud2(PointCloud(points, colors, "world"), load_interfaces().typestore.types)
    snapshot = ["kinema", "markers", "snapshot", "0", "points"]
    before = _settled_screenshot(page)
    node = Node(runtime.router, "viz_test_point_cloud")
    context = BehaviorContext(node)
    try:
        send = tick_behavior(host.registry["SendPointCloudToUI"].cls, {"point_cloud": cloud}, context=context)
        assert send.status == NodeStatus.SUCCESS, send.toasts
        page.wait_for(f"{_three(snapshot)} !== null", timeout=30)
        count = page.evaluate(f"{_three(snapshot)}.geometry.attributes.position.count")
        assert count == 20000, f"the view holds {count} points of the 57,600-point cloud, not 20,000"
        colour_array = f"{_three(snapshot)}.geometry.attributes.color.array"
        shades = page.evaluate(
            "(function(c){let r=0,g=0;for(let i=0;i<c.length;i+=3){if(c[i]>0.8&&c[i+1]<0.2)r++;"
            f"if(c[i+1]>0.7&&c[i]<0.2)g++;}}return [r,g];}})({colour_array})"
        )
        assert min(shades) > 8000, f"red and green points drawn: {shades}; the cloud's colours are lost"
        drawn = _settled_screenshot(page)
        _keep("point_cloud", drawn)
        pixels = _pixels(drawn)
        reddish = (pixels[..., 0] > 150) & (pixels[..., 1] < 90) & (pixels[..., 2] < 90)
        assert _changed(before, drawn).sum() > 500 and reddish.sum() > 200, (
            f"{_changed(before, drawn).sum()} pixels changed, {reddish.sum()} red: the cloud is not on screen"
        )
        clear = tick_behavior(host.registry["ClearSnapshot"].cls, {}, context=context)
        assert clear.status == NodeStatus.SUCCESS, clear.toasts
        page.wait_for(f"{_three(snapshot)} === null", timeout=30)
    finally:
        context.close()
        node.close()


def test_every_page_load_starts_framed_from_the_front_and_names_the_config(viewer: Any) -> None:
    # A new user saw the view start looking along the rail in 3 of 4 loads, and the wrong config named.
    view = viewer.bridge.scene.camera_view()["camera"]
    expected = [view["position"][0], view["position"][2], -view["position"][1]]  # meshcat's camera frame
    assert CHROMIUM is not None
    for _ in range(3):
        with HeadlessChromium(CHROMIUM, width=800, height=600) as browser:
            browser.navigate(viewer.url)
            browser.wait_for("typeof viewer !== 'undefined' && kinema.framed", timeout=60)
            time.sleep(1.0)  # meshcat's own start-up after the first framing
            position = browser.evaluate("JSON.stringify(viewer.camera.position.toArray())")
            np.testing.assert_allclose(json.loads(position), expected, atol=1e-6)
            browser.wait_for("document.title.indexOf('lab_sim') >= 0", timeout=10)
            assert "config lab_sim" in browser.evaluate("document.getElementById('kinema-info').textContent")
