"""The driver as a process: ``python -m kinema.drivers.mujoco``, as ``kinema run`` starts it."""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys
from collections.abc import Iterator

import pytest
from driver_harness import wait_for

from kinema.drivers import driver_spec
from kinema.drivers.mujoco import names as n
from kinema.transport import Node, open_session

# lab_sim's gripper controller (its config.yaml's robot.gripper.controller).
LAB_SIM_GRIPPER = "robotiq_gripper_controller"


def _read_ready(fd: int, process: subprocess.Popen[bytes], timeout: float) -> str:
    ready, _, _ = select.select([fd], [], [], timeout)
    if not ready:
        process.kill()
        _, stderr = process.communicate()
        raise AssertionError(f"the driver did not report ready within {timeout} s: {stderr.decode()}")
    return os.read(fd, 64).decode()


@pytest.fixture
def driver_process(router_endpoint: str) -> Iterator[subprocess.Popen[bytes]]:
    read_fd, write_fd = os.pipe()
    argv = driver_spec("mujoco").command(
        config="lab_sim", connect=router_endpoint, sim_speed="max", ready_fd=write_fd
    )
    process = subprocess.Popen(argv, pass_fds=(write_fd,), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    os.close(write_fd)
    try:
        assert _read_ready(read_fd, process, 60.0).strip() == "ready"
        yield process
    finally:
        os.close(read_fd)
        if process.poll() is None:
            process.kill()
            process.communicate()


def test_the_process_serves_and_stops_cleanly_on_sigterm(
    driver_process: subprocess.Popen[bytes], router_endpoint: str
) -> None:
    with open_session(router_endpoint) as session:
        node = Node(session, "test_client")
        clock: list[float] = []
        node.create_subscription(
            n.CLOCK_TYPE, n.CLOCK_TOPIC, lambda m: clock.append(m.clock.sec + m.clock.nanosec * 1e-9)
        )
        wait_for(lambda: len(clock) > 10, what="/clock from the driver process")
        assert clock[-1] > clock[0]
        controllers = node.create_client(n.LIST_CONTROLLERS_TYPE, n.LIST_CONTROLLERS_SERVICE).call(
            timeout=10.0
        )
        assert {c.name for c in controllers.controller} == {
            n.JOINT_STATE_BROADCASTER,
            n.FORCE_TORQUE_SENSOR_BROADCASTER,
            n.JOINT_TRAJECTORY_CONTROLLER,
            LAB_SIM_GRIPPER,
            n.JOINT_TRAJECTORY_ADMITTANCE_CONTROLLER,
            n.VELOCITY_FORCE_CONTROLLER,
        }
    driver_process.send_signal(signal.SIGTERM)
    _, stderr = driver_process.communicate(timeout=20.0)
    assert driver_process.returncode == 0, stderr.decode()


@pytest.mark.parametrize(
    ("arguments", "expected"),
    [
        (["--config", "no_such_config"], "no_such_config"),
        (["--config", "lab_sim", "--sim-speed", "fast"], "--sim-speed"),
        (["--config", "lab_sim", "--keyframe", "homme"], "home"),
    ],
)
def test_a_driver_that_cannot_start_exits_1_with_one_error_line(
    router_endpoint: str, arguments: list[str], expected: str
) -> None:
    completed = subprocess.run(
        [sys.executable, "-m", "kinema.drivers.mujoco", "--connect", router_endpoint, *arguments],
        capture_output=True,
        timeout=60.0,
    )
    assert completed.returncode == 1
    errors = [line for line in completed.stderr.decode().splitlines() if line.startswith("error: ")]
    assert len(errors) == 1, completed.stderr.decode()
    assert expected in errors[0]
    assert "Traceback" not in completed.stderr.decode()
