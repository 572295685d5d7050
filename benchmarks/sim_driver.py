"""Speed of the MuJoCo driver on lab_sim against raw ``mj_step``, measured in one run.

Prints:

* the floor: raw ``mj_step`` rate of the lab_sim scene in a Python loop (no controllers, no
  publishing) and the real-time factor it implies;
* the driver as ``kinema run`` starts it (``python -m kinema.drivers.mujoco --sim-speed max``, a
  process of its own, publishing ``/clock`` and ``/joint_states`` to a subscriber in this process):
  the real-time factor idle, and while its trajectory controller tracks a long trajectory
  (target: at least 20x on 2 cores);
* the same tracking while this process also subscribes to ``/wrist_camera/points``, the driver rendering
  it at 2 frames per wall second (``--camera-rate 2``): target, no more than 20 % below tracking without it;
* each driver figure as a fraction of the floor: each round's figure against the floor measured right
  after that round by a process of its own (the driver idling meanwhile), then the median over rounds; the
  floor is also measured before and after the driver runs, with nothing else in this process.

No assertions: numbers only. Run: ``python benchmarks/sim_driver.py [--seconds S]``; another benchmark
can print the same section with :func:`bench_sim_driver`.
"""

from __future__ import annotations

import argparse
import os
import select
import statistics
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinema.config import resolve_config
from kinema.drivers import driver_spec
from kinema.drivers.mujoco import names
from kinema.transport import Node, free_endpoint, host_router, open_session

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
# The point cloud pulled while tracking, and how often the driver renders it (frames per wall second).
POINTS_TOPIC = names.camera_topic("wrist_camera", "points")
CAMERA_RATE = 2.0


class Floor:
    """Raw mj_step of the lab_sim scene in a Python loop (no controllers, no publishing)."""

    def __init__(self) -> None:
        import mujoco

        path = resolve_config("lab_sim").mujoco_model_path
        assert path is not None
        self._mujoco = mujoco
        self.model = mujoco.MjModel.from_xml_path(str(path))
        self.data = mujoco.MjData(self.model)
        mujoco.mj_resetDataKeyframe(self.model, self.data, self.model.key("default").id)
        self.timestep = float(self.model.opt.timestep)

    def rate(self, seconds: float) -> float:
        """Steps per second over about ``seconds`` of wall time."""
        step, model, data = self._mujoco.mj_step, self.model, self.data
        steps = 0
        start = time.perf_counter()
        while time.perf_counter() - start < seconds:
            for _ in range(500):
                step(model, data)
            steps += 500
        return steps / (time.perf_counter() - start)


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


@dataclass
class Round:
    """One measurement of the driver: idle, then tracking."""

    idle: float
    tracking: float
    sim_tracked: float
    joint_states: int
    # Tracking again with a /points subscriber, and how many clouds arrived meanwhile.
    with_points: float = 0.0
    clouds: int = 0
    points_wall: float = 0.0
    # The floor measured right after this round's tracking (a process of its own, the driver idle).
    floor: float = 0.0


def floor_in_a_process(seconds: float) -> float:
    """The floor's real-time factor over ``seconds``, measured by a fresh Python process of its own."""
    completed = subprocess.run(
        [sys.executable, __file__, "--floor", str(seconds)], capture_output=True, text=True, check=True
    )
    return float(completed.stdout.strip().splitlines()[-1])


def measure(seconds: float, rounds: int) -> list[Round]:
    """Start the driver process once, then measure it idle and tracking ``rounds`` times, and the floor
    after each round (so that a machine whose load changes weighs on both alike)."""
    endpoint = free_endpoint()
    router = host_router(endpoint)
    read_fd, write_fd = os.pipe()
    spec = driver_spec("mujoco")
    argv = [
        *spec.command(config="lab_sim", connect=endpoint, sim_speed="max", ready_fd=write_fd),
        *("--camera-rate", str(CAMERA_RATE)),
    ]
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
            client = node.create_action_client(
                names.FOLLOW_JOINT_TRAJECTORY_TYPE, names.FOLLOW_JOINT_TRAJECTORY_ACTION
            )
            client.wait_for_server(10.0)
            results = []

            def track(goal: dict[str, Any]) -> tuple[float, float, float]:
                wall, sim = time.perf_counter(), watch.sim_time
                result = client.send_goal(goal, timeout=10.0).result(600.0)
                wall_elapsed = time.perf_counter() - wall
                sim_elapsed = watch.sim_time - sim
                if not result.succeeded:
                    raise SystemExit(f"the trajectory failed: {result.result.error_string}")
                return sim_elapsed / wall_elapsed, sim_elapsed, wall_elapsed

            clouds = [0]
            for _ in range(rounds):
                wall, sim = time.perf_counter(), watch.sim_time
                time.sleep(seconds / 3)
                idle = (watch.sim_time - sim) / (time.perf_counter() - wall)
                # About a third of `seconds` of wall time at the idle rate.
                leg = 2.0
                goal = back_and_forth(max(1, round(idle * seconds / 3 / (2 * leg))), leg)
                received = watch.joint_states
                tracking, sim_tracked, _ = track(goal)
                round_ = Round(idle, tracking, sim_tracked, watch.joint_states - received)
                # The same goal with a point cloud pulled (the subscription is made and dropped each
                # round, so the other measurements run without it).
                subscription = node.create_subscription(
                    names.POINT_CLOUD_TYPE,
                    POINTS_TOPIC,
                    lambda _payload: clouds.__setitem__(0, clouds[0] + 1),
                    raw=True,
                )
                try:
                    time.sleep(1.0)  # the camera thread notices the subscriber and renders a first frame
                    before = clouds[0]
                    round_.with_points, _, round_.points_wall = track(goal)
                    round_.clouds = clouds[0] - before
                finally:
                    subscription.close()
                round_.floor = floor_in_a_process(seconds / 3)
                results.append(round_)
            return results
    finally:
        os.close(read_fd)
        process.terminate()
        try:
            process.wait(20.0)
        except subprocess.TimeoutExpired:
            process.kill()
        router.close()


def bench_sim_driver(seconds: float = 6.0, rounds: int = 3) -> None:
    """Print the floor and the driver's real-time factors (idle, tracking) with their ratios (medians)."""
    print(f"lab_sim MuJoCo driver vs raw mj_step ({os.cpu_count()} cores; medians of {rounds} rounds)")
    # The floor is measured before and after the driver runs, in this process with nothing else in it
    # (the client's subscriptions would compete with the loop for the GIL); medians tame other load.
    floor_model = Floor()
    floors = [floor_model.rate(seconds / 3) * floor_model.timestep]
    results = measure(seconds, rounds)
    floors.append(floor_model.rate(seconds / 3) * floor_model.timestep)
    floor = statistics.median([*floors, *(r.floor for r in results)])
    idle = statistics.median(r.idle for r in results)
    tracking = statistics.median(r.tracking for r in results)
    # Each round's figures against the floor measured right after them, then the median of those.
    idle_ratio = statistics.median(r.idle / r.floor for r in results)
    tracking_ratio = statistics.median(r.tracking / r.floor for r in results)
    print(
        f"  floor: raw mj_step (Python loop)      {floor:6.1f}x real time   "
        f"(before/after: {floors[0]:.1f}x / {floors[1]:.1f}x; "
        f"per round: {', '.join(f'{r.floor:.1f}x' for r in results)})"
    )
    print(
        f"  driver idle, --sim-speed max          {idle:6.1f}x real time   ({idle_ratio:5.1%} of the floor)"
    )
    verdict = "met" if tracking >= 20 else "NOT met"
    print(
        f"  driver tracking a trajectory, max     {tracking:6.1f}x real time   "
        f"({tracking_ratio:5.1%} of the floor; per round: "
        f"{', '.join(f'{r.tracking / r.floor:.0%}' for r in results)})   target >= 20x: {verdict}"
    )
    with_points = statistics.median(r.with_points for r in results)
    clouds = sum(r.clouds for r in results)
    cloud_rate = clouds / max(sum(r.points_wall for r in results), 1e-9)
    loss = 1.0 - with_points / tracking
    verdict = "met" if clouds and loss <= 0.20 else "NOT met"
    points_ratio = statistics.median(r.with_points / r.floor for r in results)
    print(
        f"  ... pulling {POINTS_TOPIC} at 2 Hz {with_points:6.1f}x real time   "
        f"({points_ratio:5.1%} of the floor; loss against tracking {loss:+.0%}; "
        f"{cloud_rate:.1f} clouds/s received)   target loss <= 20%: {verdict}"
    )
    sim_tracked = sum(r.sim_tracked for r in results)
    messages = sum(r.joint_states for r in results)
    print(f"    ({sim_tracked:.1f} s of sim time tracked; {messages} /joint_states received by the client)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=6.0, help="wall seconds per round (default 6)")
    parser.add_argument("--rounds", type=int, default=3, help="interleaved rounds (default 3)")
    parser.add_argument("--smoke", action="store_true", help="one short round (the test suite)")
    parser.add_argument("--floor", type=float, default=0.0, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.floor > 0:  # the floor alone, for floor_in_a_process
        model = Floor()
        print(model.rate(args.floor) * model.timestep)
        return
    if args.smoke:
        args.seconds, args.rounds = 1.0, 1
    bench_sim_driver(args.seconds, args.rounds)


if __name__ == "__main__":
    main()
