"""Run the MuJoCo driver as a process: ``python -m kinema.drivers.mujoco --config lab_sim``.

``kinema run`` starts it this way (see :meth:`kinema.drivers.DriverSpec.command`), like the agent
(``kinema.runtime.agent_process``): it prints nothing on stdout; with ``--ready-fd N`` it writes
``ready`` to that file descriptor once every topic, service and action is served. It runs until SIGINT
or SIGTERM and exits 0, or exits 1 with one ``error:`` line when it cannot start or the physics thread
fails.
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from kinema.errors import DriverError, KinemaError
from kinema.process.stop import TERMINATE, StopRequest

log = logging.getLogger("kinema.drivers.mujoco")


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m kinema.drivers.mujoco",
        description=(
            "Simulate a config package's MuJoCo scene headless and serve its controllers "
            "(/joint_trajectory_controller/follow_joint_trajectory, /robotiq_gripper_controller/gripper_cmd, "
            "/controller_manager/*, /mujoco/*) with /clock and /joint_states, and its cameras "
            "(/<camera>/color, depth, camera_info, points) while they have subscribers."
        ),
    )
    parser.add_argument("-c", "--config", required=True, metavar="NAME", help="config package to simulate")
    parser.add_argument(
        "-w", "--workspace", type=Path, default=None, help="workspace folder (default: the active one)"
    )
    parser.add_argument(
        "-e",
        "--connect",
        metavar="ENDPOINT",
        default=None,
        help="router endpoint to join (default: $KINEMA_ZENOH_CONNECT or tcp/127.0.0.1:7447)",
    )
    parser.add_argument(
        "--host-router", metavar="ENDPOINT", default=None, help="host the router here instead of joining one"
    )
    parser.add_argument(
        "--sim-speed",
        default="1",
        metavar="FACTOR|max",
        help="sim seconds per wall second: 1 (real time, default), a factor such as 4, or max",
    )
    parser.add_argument(
        "--keyframe", default=None, help="keyframe to start from (default: the config's mujoco_keyframe)"
    )
    parser.add_argument(
        "--publish-rate",
        type=float,
        default=100.0,
        help="Hz of sim time for /clock and /joint_states (default 100)",
    )
    parser.add_argument(
        "--camera-rate",
        type=float,
        default=10.0,
        help="most frames per camera per wall second while subscribed (default 10)",
    )
    parser.add_argument(
        "--no-cameras", action="store_true", help="serve no cameras (no OpenGL context is made)"
    )
    parser.add_argument("--log-file", type=Path, default=None, help="write the log there (default: stderr)")
    parser.add_argument(
        "--ready-fd", type=int, default=None, help="write 'ready' to this file descriptor when serving"
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log at DEBUG level")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the driver until SIGINT/SIGTERM; return the exit code."""
    parser = _parser()
    args = parser.parse_args(argv)
    if not args.camera_rate > 0:
        parser.error(f"--camera-rate must be a positive number of frames a second, got {args.camera_rate:g}")
    from kinema.process import lifeline
    from kinema.process.log_files import configure_process_logging

    configure_process_logging(args.log_file, verbose=args.verbose)
    with StopRequest().handle_signals({sig: sig.name for sig in TERMINATE}) as stop:
        lifeline.hold()
        try:
            return _run(args, stop)
        except KinemaError as error:
            log.error("%s", error)
            print(f"error: {error}", file=sys.stderr)
            return 1


def _run(args: argparse.Namespace, stop: StopRequest) -> int:
    from kinema.config import Workspace
    from kinema.drivers.mujoco.driver import MujocoDriver
    from kinema.drivers.mujoco.settings import MujocoDriverSettings
    from kinema.drivers.mujoco.sim_speed import parse_sim_speed
    from kinema.transport import host_router, open_session

    overrides: dict[str, object] = {
        "sim_speed": parse_sim_speed(args.sim_speed),
        "publish_rate": args.publish_rate,
        "cameras": not args.no_cameras,
        "camera_rate": args.camera_rate,
    }
    if args.keyframe:
        overrides["keyframe"] = args.keyframe
    workspace = Workspace.discover(args.workspace) if args.workspace is not None else None
    settings = MujocoDriverSettings.from_config(args.config, workspace, **overrides)
    session = host_router(args.host_router) if args.host_router else open_session(args.connect)
    with session:
        from kinema.transport.presence import DRIVER, declare_presence

        # Announced before its nodes exist, so whoever sees them also knows whose they are.
        declare_presence(session, DRIVER, name="mujoco", config=args.config, endpoint=args.connect or "")
        driver = MujocoDriver(session, settings)
        driver.start()
        if args.ready_fd is not None:
            with os.fdopen(args.ready_fd, "w") as ready:
                ready.write("ready\n")
        try:
            while not stop.wait(0.2):
                if driver.failure is not None:
                    raise DriverError(f"the simulation failed: {driver.failure}")
            log.info("received %s; stopping", stop.reason)
        finally:
            driver.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
