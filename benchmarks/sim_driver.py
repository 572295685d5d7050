"""Speed of the MuJoCo driver on lab_sim against raw ``mj_step``, measured in one run.

Prints:

* the floor: raw ``mj_step`` rate of the lab_sim scene in a Python loop (no controllers, no
  publishing) and the real-time factor it implies;
* the driver as ``kinema run`` starts it (``python -m kinema.drivers.mujoco --sim-speed max``, a
  process of its own, publishing ``/clock`` and ``/joint_states`` to a subscriber in this process):
  the real-time factor idle, and while its trajectory controller tracks a long trajectory
  (target: at least 20x on 2 cores);
* each driver figure as a fraction of the floor.

No assertions: numbers only. Run: ``python benchmarks/sim_driver.py [--seconds S]``.
"""

from __future__ import annotations

import argparse
import os
import select
import socket
import subprocess
import threading
import time
from typing import Any

import numpy as np

from kinema.config import resolve_config
from kinema.drivers import driver_spec
from kinema.drivers.mujoco import names
from kinema.transport import Node, host_router, open_session

ARM = (
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
DEFAULT = np.array([0.0, 0.0, -2.0, 2.0, -1.5708, -1.5708, 0.0])
AWAY = DEFAULT + np.array([0.3, 0.8, 0.3, -0.3, 0.6, 0.6, 1.0])


def free_endpoint() -> str:
    """A loopback endpoint on a port the OS reports free."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{probe.getsockname()[1]}"


def floor_rate(seconds: float) -> tuple[float, float]:
    """Raw mj_step steps/s of the scene at its default keyframe, and the timestep."""
    import mujoco

    path = resolve_config("lab_sim").mujoco_model_path
    assert path is not None
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("default").id)
    for _ in range(500):
        mujoco.mj_step(model, data)
    steps = 0
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        for _ in range(1000):
            mujoco.mj_step(model, data)
        steps += 1000
    return steps / (time.perf_counter() - start), float(model.opt.timestep)


def back_and_forth(cycles: int, leg: float) -> dict[str, Any]:
    """A FollowJointTrajectory goal going DEFAULT -> AWAY -> DEFAULT ``cycles`` times, ``leg`` s per leg."""
    points = []
    for k in range(2 * cycles):
        a, b = (DEFAULT, AWAY) if k % 2 == 0 else (AWAY, DEFAULT)
        for t in np.linspace(0.0, leg, 11)[(1 if k else 0) :]:
            s = t / leg
            shape = 10 * s**3 - 15 * s**4 + 6 * s**5
            rate = (30 * s**2 - 60 * s**3 + 30 * s**4) / leg
            stamp = round((k * leg + t) * 1e9)
            points.append(
                {
                    "positions": (a + (b - a) * shape).tolist(),
                    "velocities": ((b - a) * rate).tolist(),
                    "time_from_start": {"sec": stamp // 10**9, "nanosec": stamp % 10**9},
                }
            )
    return {"trajectory": {"joint_names": list(ARM), "points": points}}


class ClockWatch:
    """The latest ``/clock`` stamp (and how many joint states arrived)."""

    def __init__(self, node: Node) -> None:
        self.sim_time = 0.0
        self.joint_states = 0
        self._ticked = threading.Event()
        node.create_subscription(names.CLOCK_TYPE, names.CLOCK_TOPIC, self._on_clock)
        node.create_subscription(
            names.JOINT_STATES_TYPE, names.JOINT_STATES_TOPIC, self._on_joint_state, raw=True
        )

    def _on_clock(self, message: Any) -> None:
        self.sim_time = message.clock.sec + message.clock.nanosec * 1e-9
        self._ticked.set()

    def _on_joint_state(self, _payload: bytes) -> None:
        self.joint_states += 1

    def wait(self, timeout: float = 30.0) -> None:
        if not self._ticked.wait(timeout):
            raise SystemExit("no /clock from the driver")


def measure_driver(seconds: float) -> tuple[float, float, float, int]:
    """Real-time factor of the driver process idle and while tracking; sim seconds tracked, messages."""
    endpoint = free_endpoint()
    router = host_router(endpoint)
    read_fd, write_fd = os.pipe()
    argv = driver_spec("mujoco").command(
        config="lab_sim", connect=endpoint, sim_speed="max", ready_fd=write_fd
    )
    process = subprocess.Popen(argv, pass_fds=(write_fd,), stderr=subprocess.PIPE)
    os.close(write_fd)
    try:
        if not select.select([read_fd], [], [], 60.0)[0]:
            raise SystemExit(
                "the driver did not start: " + (process.stderr.read().decode() if process.stderr else "")
            )
        with open_session(endpoint) as session:
            node = Node(session, "benchmark")
            watch = ClockWatch(node)
            watch.wait()
            wall, sim = time.perf_counter(), watch.sim_time
            time.sleep(min(seconds, 2.0))
            idle = (watch.sim_time - sim) / (time.perf_counter() - wall)
            client = node.create_action_client(
                names.FOLLOW_JOINT_TRAJECTORY_TYPE, names.FOLLOW_JOINT_TRAJECTORY_ACTION
            )
            client.wait_for_server(10.0)
            # Long enough to take about `seconds` of wall time at the idle rate.
            leg = 2.0
            cycles = max(1, round(idle * seconds / (2 * leg)))
            goal = back_and_forth(cycles, leg)
            received = watch.joint_states
            wall, sim = time.perf_counter(), watch.sim_time
            result = client.send_goal(goal, timeout=10.0).result(600.0)
            wall_elapsed = time.perf_counter() - wall
            sim_elapsed = watch.sim_time - sim
            if not result.succeeded:
                raise SystemExit(f"the trajectory failed: {result.result.error_string}")
            return idle, sim_elapsed / wall_elapsed, sim_elapsed, watch.joint_states - received
    finally:
        os.close(read_fd)
        process.terminate()
        try:
            process.wait(20.0)
        except subprocess.TimeoutExpired:
            process.kill()
        router.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=5.0, help="wall seconds per measurement (default 5)")
    args = parser.parse_args()
    print(f"lab_sim MuJoCo driver vs raw mj_step ({os.cpu_count()} cores)")
    rate, timestep = floor_rate(min(args.seconds, 3.0))
    floor = rate * timestep
    print(f"  floor: raw mj_step                    {rate:10,.0f} steps/s = {floor:6.1f}x real time")
    idle, tracking, sim_tracked, messages = measure_driver(args.seconds)
    print(
        f"  driver idle, --sim-speed max          {idle:6.1f}x real time   ({idle / floor:5.1%} of the floor)"
    )
    verdict = "met" if tracking >= 20 else "NOT met"
    print(
        f"  driver tracking a trajectory, max     {tracking:6.1f}x real time   "
        f"({tracking / floor:5.1%} of the floor)   target >= 20x: {verdict}"
    )
    print(f"    ({sim_tracked:.1f} s of sim time tracked; {messages} /joint_states received by the client)")


if __name__ == "__main__":
    main()
