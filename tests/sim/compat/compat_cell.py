"""Helpers for the lab_sim objective tests: the temporary config package and a running cell.

A lab_sim cell for objective tests: router, MuJoCo driver and agent in this process, an SDK client.

The config package under test lives in a temporary workspace and is based on lab_sim. For the
compatibility tests its objective library is a copy of ``../shared/compat/moveit_pro/objectives/``
made at test time (never committed); for Kinema's own objectives it is lab_sim itself. The driver runs
at max sim speed unless a test asks otherwise; positions come from the simulator (``/mujoco/bodies``).
"""

from __future__ import annotations

import shutil
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from kinema.resources import bundled_dir

CONFIG = "compat_lab_sim"
# Where "3 Waypoints Pick and Place" puts the cube: its start on the table, and the tray (the grasp
# point at the place waypoint, 20 mm above the cube's centre; see configs/lab_sim/description/README.md).
PICK_POSITION = np.array([-0.30, 0.62, 0.499])
PLACE_POSITION = np.array([0.30, 0.62, 0.503])
TOLERANCE = 0.02
ARM = (
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
# A waypoint the arm cannot reach: the tool driven down through the table top.
UNREACHABLE_WAYPOINT = {
    "name": "Through the Table",
    "description": "tool below the table top (for fault tests)",
    "favorite": False,
    "joint_group_names": ["manipulator"],
    "joint_state": {
        "name": list(ARM),
        "position": [0.0, 0.0, -0.3, 1.9, -1.6, -1.5708, 0.0],
        "velocity": [],
        "effort": [],
    },
}


def wait_for(predicate: Callable[[], Any], timeout: float, what: str) -> Any:
    """Poll ``predicate`` until it returns something truthy; fail the test after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.01)
    raise AssertionError(f"timed out after {timeout} s waiting for {what}")


def make_workspace(root: Path, objectives: Path | None) -> Path:
    """A workspace with config package ``compat_lab_sim`` (based on lab_sim).

    Args:
        root: an empty folder to create the workspace in.
        objectives: a folder of objectives to copy in as the config's only objective library; None
            keeps lab_sim's libraries (Kinema's own objectives).
    """
    package = root / "src" / CONFIG
    (package / "config").mkdir(parents=True)
    (package / "waypoints").mkdir()
    (package / "package.xml").write_text(
        f'<?xml version="1.0"?>\n<package format="3"><name>{CONFIG}</name><version>0.0.0</version>'
        "<description>lab_sim under test</description><maintainer email='t@example.com'>t</maintainer>"
        "<license>BSD-3-Clause</license></package>\n"
    )
    waypoints_file = bundled_dir("configs") / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml"
    waypoints = yaml.safe_load(waypoints_file.read_text())
    waypoints.append(UNREACHABLE_WAYPOINT)
    (package / "waypoints" / "waypoints.yaml").write_text(yaml.safe_dump(waypoints, sort_keys=False))
    config: dict[str, Any] = {
        "based_on_package": "lab_sim",
        "objectives": {
            "waypoints_file": {"package_name": CONFIG, "relative_path": "waypoints/waypoints.yaml"},
        },
    }
    if objectives is not None:
        shutil.copytree(objectives, package / "objectives")
        (package / "no_objectives").mkdir()
        # Replace both of lab_sim's libraries: the copied MoveIt Pro files bring their own
        # "Move to Waypoint" and "Move to Joint State", which must not meet Kinema's.
        config["objectives"]["objective_library_paths"] = {
            "core_objectives": {"package_name": CONFIG, "relative_path": "objectives"},
            "lab_sim_objectives": {"package_name": CONFIG, "relative_path": "no_objectives"},
        }
    (package / "config" / "config.yaml").write_text(yaml.safe_dump(config, sort_keys=False))
    return root


@dataclass
class Cell:
    """A running lab_sim cell: driver, agent, SDK client and a probe node."""

    driver: Any
    agent: Any
    client: Any
    node: Any
    workspace: Path
    endpoint: str
    _bodies: Any = None
    _joint_states: list[Any] = field(default_factory=list)
    _lock: threading.Lock = field(default_factory=threading.Lock)

    def cube(self) -> np.ndarray:
        """The cube's world position, from the simulator."""
        if self._bodies is None:
            self._bodies = self.node.create_client("kinema_msgs/srv/GetSimBodies", "/mujoco/bodies")
        response = self._bodies.call({}, timeout=10.0)
        for body in response.bodies:
            if body.name == "cube":
                p = body.pose.position
                return np.array([p.x, p.y, p.z])
        raise AssertionError(f"no cube among the simulator's bodies: {[b.name for b in response.bodies]}")

    def record_joint_states(self) -> None:
        """Keep every ``/joint_states`` message from now on (see :meth:`joint_history`)."""
        self.node.create_subscription("sensor_msgs/msg/JointState", "/joint_states", self._on_joint_state)

    def _on_joint_state(self, message: Any) -> None:
        stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
        index = {n: i for i, n in enumerate(message.name)}
        positions = np.array([message.position[index[n]] for n in ARM])
        velocities = np.array([message.velocity[index[n]] for n in ARM])
        with self._lock:
            self._joint_states.append((stamp, positions, velocities))

    def describe(self) -> str:
        """For a failing test: the cell's endpoint, sim time and the arm's last recorded state."""
        sim_time = f"{self.driver.sim_time:.3f} s" if self.driver is not None else "(no driver here)"
        with self._lock:
            last = self._joint_states[-1] if self._joint_states else None
        arm = (
            f"arm at {np.round(last[1], 4).tolist()} rad, velocities {np.round(last[2], 3).tolist()} "
            f"(stamp {last[0]:.3f} s)"
            if last is not None
            else "arm not recorded"
        )
        return f"cell at {self.endpoint}: sim time {sim_time}; {arm}"

    def joint_history(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(stamps, positions, velocities)`` of the arm joints received so far."""
        with self._lock:
            rows = list(self._joint_states)
        return (
            np.array([r[0] for r in rows]),
            np.array([r[1] for r in rows]),
            np.array([r[2] for r in rows]),
        )
