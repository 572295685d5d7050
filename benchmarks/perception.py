"""Speed of lab_sim's simulated cameras, measured in one run.

Prints:

* per frame of ``scene_camera`` at 640x480 (medians): the colour image, the depth image, and the
  organised point cloud as the driver serves it (depth and colour render, back-projection, PointCloud2
  built and serialised to CDR) — each also as a multiple of MuJoCo's own ``Renderer.render()`` of the
  same image, the peer measured alongside (target: a cloud in under 100 ms on 2 cores);
* the driver as ``kinema run`` starts it (``python -m kinema.drivers.mujoco --sim-speed max``, a process
  of its own): its real-time factor started with ``--no-cameras``, then with cameras and nobody on them,
  and with a client here pulling a cloud from ``/scene_camera/points`` every 0.5 s as GetPointCloud does
  (subscribe, take one, unsubscribe), interleaved with the idle rounds (target: under 20 % of the
  real-time factor lost).

No assertions: numbers only. Run: ``python benchmarks/perception.py [--seconds S] [--rounds N]``.
Needs OpenGL (headless: ``sudo apt-get install -y libegl1 libgl1 libgl1-mesa-dri``).
"""

from __future__ import annotations

import argparse
import os
import select
import statistics
import subprocess
import threading
import time
from collections.abc import Callable
from typing import Any

from kinema.config import resolve_config
from kinema.drivers import driver_spec
from kinema.drivers.mujoco import names
from kinema.transport import Node, free_endpoint, host_router, open_session

CAMERA = "scene_camera"


def _median_ms(action: Callable[[], Any], count: int) -> float:
    times = []
    for _ in range(count):
        start = time.perf_counter()
        action()
        times.append(time.perf_counter() - start)
    return 1000.0 * statistics.median(times)


def bench_frames(count: int) -> dict[str, float]:
    """Median ms per colour frame, depth frame and served cloud, and MuJoCo's raw renders beside them."""
    import mujoco

    from kinema.drivers.mujoco.cameras import GL_HELP, CameraRenderer, SimState, camera_specs
    from kinema.interfaces import load_interfaces
    from kinema.perception.ros_messages import to_point_cloud2

    path = resolve_config("lab_sim").mujoco_model_path
    assert path is not None
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("default").id)
    mujoco.mj_forward(model, data)
    try:
        renderer = CameraRenderer(model)
    except Exception as error:
        raise SystemExit(f"cannot render: {error}. {GL_HELP}") from error
    spec = next(s for s in camera_specs(model) if s.name == CAMERA)
    registry = load_interfaces()
    types = registry.typestore.types
    renderer.set_state(SimState.of(data))
    raw = mujoco.Renderer(model, spec.intrinsics.height, spec.intrinsics.width)

    def raw_color() -> None:
        raw.update_scene(data, camera=CAMERA)
        raw.render()

    def raw_depth() -> None:
        raw.enable_depth_rendering()
        raw.update_scene(data, camera=CAMERA)
        raw.render()
        raw.disable_depth_rendering()

    def cloud() -> None:
        frame = renderer.render(spec, color=True, depth=True)
        message = to_point_cloud2(frame.cloud(), types)
        registry.serialize(message, names.POINT_CLOUD_TYPE)

    for action in (raw_color, raw_depth, cloud):  # warm up: shaders, buffers
        action()
    results = {
        "raw colour": _median_ms(raw_color, count),
        "colour": _median_ms(lambda: renderer.render(spec, color=True, depth=False), count),
        "raw depth": _median_ms(raw_depth, count),
        "depth": _median_ms(lambda: renderer.render(spec, color=False, depth=True), count),
        "cloud": _median_ms(cloud, count),
    }
    raw.close()
    renderer.close()
    return results


class Watch:
    """The driver's /clock, and clouds pulled at a period on request."""

    def __init__(self, node: Node) -> None:
        self.node = node
        self.sim_time = 0.0
        self.clouds = 0
        self._ticked = threading.Event()
        node.create_subscription(names.CLOCK_TYPE, names.CLOCK_TOPIC, self._on_clock)

    def _on_clock(self, message: Any) -> None:
        self.sim_time = message.clock.sec + message.clock.nanosec * 1e-9
        self._ticked.set()

    def wait(self, timeout: float = 60.0) -> None:
        if not self._ticked.wait(timeout):
            raise SystemExit("no /clock from the driver")

    def pull_cloud(self, timeout: float = 30.0) -> None:
        """Subscribe to the cloud topic, wait for one message, unsubscribe (as GetPointCloud does)."""
        arrived = threading.Event()
        subscription = self.node.create_subscription(
            names.POINT_CLOUD_TYPE,
            names.camera_topic(CAMERA, "points"),
            lambda _payload: arrived.set(),
            raw=True,
        )
        try:
            if not arrived.wait(timeout):
                raise SystemExit(f"no cloud on {names.camera_topic(CAMERA, 'points')} within {timeout} s")
            self.clouds += 1
        finally:
            subscription.close()


def bench_real_time_factor(
    seconds: float, rounds: int, *, cameras: bool = True
) -> tuple[list[float], list[float], int]:
    """Real-time factors of the driver process: without camera subscribers, and pulling a cloud at 2 Hz
    (with ``cameras=False`` a driver started with ``--no-cameras``, idle rounds only)."""
    endpoint = free_endpoint()
    router = host_router(endpoint)
    read_fd, write_fd = os.pipe()
    argv = driver_spec("mujoco").command(
        config="lab_sim", connect=endpoint, sim_speed="max", ready_fd=write_fd
    )
    if not cameras:
        argv.append("--no-cameras")
    process = subprocess.Popen(argv, pass_fds=(write_fd,), stderr=subprocess.PIPE)
    os.close(write_fd)
    idle: list[float] = []
    pulling: list[float] = []
    try:
        if not select.select([read_fd], [], [], 60.0)[0]:
            raise SystemExit(
                "the driver did not start: " + (process.stderr.read().decode() if process.stderr else "")
            )
        with open_session(endpoint) as session:
            watch = Watch(Node(session, "benchmark"))
            watch.wait()
            if cameras:
                watch.pull_cloud(120.0)  # the first frame makes the OpenGL context, compiles shaders
            time.sleep(1.0)
            for _ in range(rounds):
                wall, sim = time.perf_counter(), watch.sim_time
                time.sleep(seconds)
                idle.append((watch.sim_time - sim) / (time.perf_counter() - wall))
                if not cameras:
                    continue
                wall, sim = time.perf_counter(), watch.sim_time
                while time.perf_counter() - wall < seconds:
                    started = time.perf_counter()
                    watch.pull_cloud()
                    time.sleep(max(0.0, 0.5 - (time.perf_counter() - started)))
                pulling.append((watch.sim_time - sim) / (time.perf_counter() - wall))
        return idle, pulling, watch.clouds
    finally:
        os.close(read_fd)
        process.terminate()
        try:
            process.wait(20.0)
        except subprocess.TimeoutExpired:
            process.kill()
        router.close()


def bench_perception(seconds: float = 6.0, rounds: int = 3, frames: int = 20) -> None:
    """Print frame times and the real-time factor with and without a 2 Hz cloud subscriber."""
    print(f"lab_sim cameras ({os.cpu_count()} cores, MUJOCO_GL={os.environ.get('MUJOCO_GL', 'egl')})")
    times = bench_frames(frames)
    print(f"  per frame, {CAMERA} 640x480, medians of {frames}:")
    print(
        f"    colour image                 {times['colour']:7.1f} ms   "
        f"({times['colour'] / times['raw colour']:.2f}x MuJoCo's Renderer.render, "
        f"{times['raw colour']:.1f} ms)"
    )
    print(
        f"    depth image                  {times['depth']:7.1f} ms   "
        f"({times['depth'] / times['raw depth']:.2f}x MuJoCo's depth render, {times['raw depth']:.1f} ms)"
    )
    verdict = "met" if times["cloud"] < 100 else "NOT met"
    print(
        f"    point cloud (colour + depth, PointCloud2 in CDR) {times['cloud']:7.1f} ms   "
        f"({times['cloud'] / (times['raw colour'] + times['raw depth']):.2f}x the two raw renders)   "
        f"target < 100 ms: {verdict}"
    )
    without, _, _ = bench_real_time_factor(seconds, rounds, cameras=False)
    idle, pulling, clouds = bench_real_time_factor(seconds, rounds)
    without_median = statistics.median(without)
    idle_median, pulling_median = statistics.median(idle), statistics.median(pulling)
    loss = 1.0 - pulling_median / idle_median
    verdict = "met" if loss < 0.20 else "NOT met"
    print(f"  driver process, --sim-speed max, medians of {rounds} rounds of {seconds:g} s:")
    rounds_without = ", ".join(f"{v:.1f}" for v in without)
    print(f"    --no-cameras                 {without_median:7.1f}x real time   ({rounds_without})")
    rounds_idle = ", ".join(f"{v:.1f}" for v in idle)
    print(
        f"    cameras, nobody on them      {idle_median:7.1f}x real time   ({rounds_idle}; "
        f"{idle_median / without_median:.0%} of --no-cameras)"
    )
    print(
        f"    a cloud pulled every 0.5 s   {pulling_median:7.1f}x real time   "
        f"({', '.join(f'{v:.1f}' for v in pulling)}; {clouds} clouds)"
    )
    print(f"    real-time factor lost to the 2 Hz cloud: {loss:.1%}   target < 20 %: {verdict}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=6.0, help="wall seconds per round (default 6)")
    parser.add_argument("--rounds", type=int, default=3, help="interleaved rounds (default 3)")
    parser.add_argument("--frames", type=int, default=20, help="frames per render timing (default 20)")
    parser.add_argument("--smoke", action="store_true", help="short rounds, few frames (the test suite)")
    args = parser.parse_args()
    if args.smoke:
        args.seconds, args.rounds, args.frames = 1.0, 1, 2
    bench_perception(args.seconds, args.rounds, args.frames)


if __name__ == "__main__":
    main()
