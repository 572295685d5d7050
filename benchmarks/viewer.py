"""What streaming the 3D view costs the simulation: lab_sim's real-time factor, ``kinema view`` off vs on.

The driver runs as ``kinema run`` starts it (``python -m kinema.drivers.mujoco --sim-speed max``, a process
of its own) while its trajectory controller tracks a long back-and-forth trajectory. In alternating
rounds the viewer process (``python -m kinema.viz --no-browser``, subscribed to ``/joint_states``,
``/mujoco/scene_state``, ``/clock`` and the agent's topics, drawing at 60 Hz) is off, then on, then off
... and, with ``--browser``, a headless Chromium page renders the view too. The real-time factor is sim
seconds per wall second, read from the stamps of the driver's scene-state topic (30 Hz wall), so the
measurement itself adds almost nothing. Target: less than 10 % drop with the view on.

A second section runs the driver at real time (speed 1) and reports how many scene updates per second
the view draws (target: at least 30).

No assertions: numbers only. Run: ``python benchmarks/viewer.py [--seconds S] [--rounds N] [--browser]``.
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import statistics
import subprocess
import sys
import threading
import time
import urllib.request
from pathlib import Path
from typing import Any

import numpy as np

from kinema.drivers.mujoco import names
from kinema.transport import Node, free_endpoint, host_router

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
AWAY = HOME + np.array([0.3, 1.2, 0.4, -0.5, 0.3, 0.0, 0.5])


def back_and_forth(cycles: int, leg: float) -> dict[str, Any]:
    """A FollowJointTrajectory goal: HOME → AWAY → HOME ... (smooth legs of ``leg`` sim seconds)."""
    rows = []
    for cycle in range(cycles):
        for step in range(21):
            s = step / 20
            shape = 10 * s**3 - 15 * s**4 + 6 * s**5
            a, b = (HOME, AWAY) if cycle % 2 == 0 else (AWAY, HOME)
            t = cycle * leg + s * leg
            if rows and step == 0:
                continue
            nanoseconds = round(t * 1e9)
            rows.append(
                {
                    "positions": (a + (b - a) * shape).tolist(),
                    "time_from_start": {"sec": nanoseconds // 10**9, "nanosec": nanoseconds % 10**9},
                }
            )
    return {"trajectory": {"joint_names": list(ARM), "points": rows}}


class SimClock:
    """Sim time from the driver's scene-state stamps (published at 30 Hz of wall time)."""

    def __init__(self, node: Node) -> None:
        self._latest: tuple[float, float] | None = None
        self._lock = threading.Lock()
        node.create_subscription(names.SCENE_STATE_TYPE, names.SCENE_STATE_TOPIC, self._on_state)

    def _on_state(self, state: Any) -> None:
        with self._lock:
            self._latest = (time.perf_counter(), state.stamp.sec + state.stamp.nanosec * 1e-9)

    def sample(self) -> tuple[float, float]:
        deadline = time.monotonic() + 10
        while self._latest is None and time.monotonic() < deadline:
            time.sleep(0.01)
        with self._lock:
            assert self._latest is not None, "no scene state from the driver"
            return self._latest

    def factor(self, seconds: float) -> float:
        """Sim seconds per wall second over the next ``seconds``."""
        wall0, sim0 = self.sample()
        time.sleep(seconds)
        wall1, sim1 = self.sample()
        return (sim1 - sim0) / (wall1 - wall0)


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def start_driver(endpoint: str, speed: str) -> subprocess.Popen[bytes]:
    read_fd, write_fd = os.pipe()
    process = subprocess.Popen(
        [
            *(sys.executable, "-m", "kinema.drivers.mujoco", "-c", "lab_sim", "-e", endpoint),
            *("--sim-speed", speed, "--ready-fd", str(write_fd)),
        ],
        pass_fds=(write_fd,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(write_fd)
    with os.fdopen(read_fd) as ready:
        if ready.readline().strip() != "ready":
            raise SystemExit("the driver did not start")
    return process


class ViewerProcess:
    """``python -m kinema.viz --no-browser`` (and optionally a headless Chromium page on it)."""

    def __init__(self, endpoint: str, browser: bool) -> None:
        read_fd, write_fd = os.pipe()
        self.process = subprocess.Popen(
            [
                *(sys.executable, "-m", "kinema.viz", "--connect", endpoint, "--config", "lab_sim"),
                *("--no-browser", "--port", str(_free_port()), "--ready-fd", str(write_fd)),
            ],
            pass_fds=(write_fd,),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        os.close(write_fd)
        with os.fdopen(read_fd) as ready:
            self.url = ready.readline().strip()
        if not self.url.startswith("http"):
            raise SystemExit(f"the viewer did not start: {self.url}")
        self.page: Any = None
        if browser:
            sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "viz"))
            from headless_chromium import HeadlessChromium, find_chromium

            executable = find_chromium()
            if executable is None:
                raise SystemExit("--browser needs chromium (apt-get install -y chromium)")
            self.page = HeadlessChromium(executable, width=800, height=600)
            self.page.navigate(self.url)
            self.page.wait_for(
                "typeof viewer !== 'undefined' && viewer.num_messages_received > 30", timeout=60
            )

    def status(self) -> dict[str, Any]:
        with urllib.request.urlopen(self.url.replace("/static/", "/kinema/status.json"), timeout=5) as answer:
            return dict(json.loads(answer.read()))

    def close(self) -> None:
        if self.page is not None:
            self.page.close()
        self.process.terminate()
        self.process.wait(10)


def measure_cost(seconds: float, rounds: int, browser: bool) -> None:
    endpoint = free_endpoint()
    router = host_router(endpoint)
    driver = start_driver(endpoint, "max")
    node = Node(router, "viewer_benchmark")
    try:
        clock = SimClock(node)
        client = node.create_action_client(
            names.FOLLOW_JOINT_TRAJECTORY_TYPE, names.FOLLOW_JOINT_TRAJECTORY_ACTION
        )
        handle = client.send_goal(back_and_forth(4000, 3.0), timeout=10.0)
        assert handle.accepted, "the driver refused the benchmark trajectory"
        clock.factor(1.0)  # warm up
        off: list[float] = []
        on: list[float] = []
        rates: list[float] = []
        for _ in range(rounds):
            off.append(clock.factor(seconds))
            viewer = ViewerProcess(endpoint, browser)
            try:
                clock.factor(1.0)  # let it settle (start-up, first scene push)
                on.append(clock.factor(seconds))
                rates.append(float(viewer.status()["info"].rsplit("·", 1)[1].split()[0]))
            finally:
                viewer.close()
        off.append(clock.factor(seconds))
        handle.cancel()
    finally:
        node.close()
        driver.terminate()
        driver.wait(10)
        router.close()
    off_median, on_median = statistics.median(off), statistics.median(on)
    what = "viewer process + headless Chromium page" if browser else "viewer process (no browser)"
    print(f"lab_sim driver at --sim-speed max, tracking a trajectory; view = {what}")
    for label, median, values in (("off", off_median, off), ("on ", on_median, on)):
        rounds_text = ", ".join(f"{v:.1f}" for v in values)
        print(f"  real-time factor, view {label}: median {median:6.1f}x  (rounds: {rounds_text})")
    print(f"  drop with the view on     : {100 * (1 - on_median / off_median):5.1f} %   (target < 10 %)")
    print(f"  view updates drawn        : median {statistics.median(rates):.0f}/s")


def measure_rate(seconds: float, browser: bool) -> None:
    endpoint = free_endpoint()
    router = host_router(endpoint)
    driver = start_driver(endpoint, "1")
    node = Node(router, "viewer_benchmark")
    viewer = None
    try:
        client = node.create_action_client(
            names.FOLLOW_JOINT_TRAJECTORY_TYPE, names.FOLLOW_JOINT_TRAJECTORY_ACTION
        )
        handle = client.send_goal(back_and_forth(100, 3.0), timeout=10.0)
        viewer = ViewerProcess(endpoint, browser)
        time.sleep(1.0)
        first = viewer.status()
        started = time.monotonic()
        time.sleep(seconds)
        last = viewer.status()
        rate = (last["state_updates"] - first["state_updates"]) / (time.monotonic() - started)
        handle.cancel()
    finally:
        if viewer is not None:
            viewer.close()
        node.close()
        driver.terminate()
        driver.wait(10)
        router.close()
    print("lab_sim driver at real time (speed 1), arm moving")
    print(f"  scene updates drawn by the view: {rate:.1f}/s   (target >= 30)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=4.0, help="wall seconds per measurement (default 4)")
    parser.add_argument("--rounds", type=int, default=3, help="off/on rounds (default 3)")
    parser.add_argument("--browser", action="store_true", help="also render the page in headless Chromium")
    parser.add_argument("--smoke", action="store_true", help="one short round (the test suite)")
    args = parser.parse_args()
    if args.smoke:
        args.seconds, args.rounds = 1.0, 1
    measure_cost(args.seconds, args.rounds, args.browser)
    measure_rate(args.seconds, args.browser)


if __name__ == "__main__":
    main()
