"""Helpers for the MuJoCo driver tests: a client view of a running driver, joint state history,
smooth trajectories. (A module of its own, not the conftest: test modules import these by name, and
``conftest`` is a name every test folder uses.)

Times in assertions are sim times read from ``/joint_states`` stamps, never wall time.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from kinema.drivers.mujoco import MujocoDriver
from kinema.drivers.mujoco import names as n
from kinema.transport import Node

# lab_sim's gripper controller (its config.yaml's robot.gripper.controller).
LAB_SIM_GRIPPER = "robotiq_gripper_controller"

ARM = (
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
GRIPPER = "robotiq_85_left_knuckle_joint"


def wait_for(predicate: Callable[[], Any], timeout: float = 10.0, what: str = "condition") -> Any:
    """Poll ``predicate`` until it returns something truthy; fail the test after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.005)
    raise AssertionError(f"timed out after {timeout} s waiting for {what}")


@dataclass
class JointStates:
    """Every ``/joint_states`` message received: ``stamps`` (sim s) and ``positions`` (rows by name)."""

    names: list[str] = field(default_factory=list)
    stamps: list[float] = field(default_factory=list)
    positions: list[np.ndarray] = field(default_factory=list)
    velocities: list[np.ndarray] = field(default_factory=list)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def on_message(self, message: Any) -> None:
        with self.lock:
            self.names = list(message.name)
            self.stamps.append(message.header.stamp.sec + message.header.stamp.nanosec * 1e-9)
            self.positions.append(np.array(message.position, dtype=float))
            self.velocities.append(np.array(message.velocity, dtype=float))

    def latest(self, joints: tuple[str, ...] = ARM) -> np.ndarray:
        """The latest positions of ``joints``."""
        wait_for(lambda: self.stamps, what="a /joint_states message")
        with self.lock:
            row = self.positions[-1]
            return np.array([row[self.names.index(j)] for j in joints])

    def latest_stamp(self) -> float:
        wait_for(lambda: self.stamps, what="a /joint_states message")
        with self.lock:
            return self.stamps[-1]

    def history(self, joints: tuple[str, ...] = ARM) -> tuple[np.ndarray, np.ndarray]:
        """``(stamps, positions)`` of everything received, positions of ``joints`` only."""
        with self.lock:
            columns = [self.names.index(j) for j in joints]
            return np.array(self.stamps), np.array([row[columns] for row in self.positions])

    def wait_until(self, sim_time: float, timeout: float = 20.0) -> None:
        """Block until a message stamped at or after ``sim_time`` arrived."""
        wait_for(lambda: self.stamps and self.stamps[-1] >= sim_time, timeout, f"sim time {sim_time:.3f} s")


@dataclass
class Sim:
    """A running driver and a client node that talks to it."""

    driver: MujocoDriver
    node: Node
    joint_states: JointStates
    clients: dict[str, Any] = field(default_factory=dict)

    def action(self, name: str, type_name: str) -> Any:
        key = f"{type_name}:{name}"  # one action name may be served with two types (the admittance's)
        if key not in self.clients:
            client = self.node.create_action_client(type_name, name)
            assert client.wait_for_server(10.0), f"{name} is not served"
            self.clients[key] = client
        return self.clients[key]

    def service(self, name: str, type_name: str) -> Any:
        key = f"srv:{name}"
        if key not in self.clients:
            client = self.node.create_client(type_name, name)
            assert client.wait_for_service(10.0), f"{name} is not served"
            self.clients[key] = client
        return self.clients[key]

    def follow(self, goal: dict[str, Any], feedback: Callable[[Any], Any] | None = None) -> Any:
        """Send a FollowJointTrajectory goal; return its handle."""
        client = self.action(n.FOLLOW_JOINT_TRAJECTORY_ACTION, n.FOLLOW_JOINT_TRAJECTORY_TYPE)
        return client.send_goal(goal, feedback, timeout=10.0)

    def gripper(self, position: float, max_effort: float = 0.0) -> Any:
        """Run a GripperCommand goal to the end; return its GoalResult."""
        client = self.action(n.gripper_command_action(LAB_SIM_GRIPPER), n.GRIPPER_COMMAND_TYPE)
        handle = client.send_goal({"command": {"position": position, "max_effort": max_effort}}, timeout=10.0)
        return handle.result(30.0)

    def set_state(self, keyframe: str = "", **positions: float) -> Any:
        client = self.service(n.SET_STATE_SERVICE, n.SET_STATE_TYPE)
        request = {
            "keyframe": keyframe,
            "joint_state": {"name": list(positions), "position": list(positions.values())},
        }
        return client.call(request, timeout=10.0)

    def switch(
        self, activate: Sequence[str] = (), deactivate: Sequence[str] = (), strictness: int = 2
    ) -> Any:
        client = self.service(n.SWITCH_CONTROLLERS_SERVICE, n.SWITCH_CONTROLLERS_TYPE)
        request = {
            "activate_controllers": list(activate),
            "deactivate_controllers": list(deactivate),
            "strictness": strictness,
        }
        return client.call(request, timeout=10.0)

    def controllers(self) -> dict[str, Any]:
        client = self.service(n.LIST_CONTROLLERS_SERVICE, n.LIST_CONTROLLERS_TYPE)
        return {c.name: c for c in client.call(timeout=10.0).controller}

    def settle(self, seconds: float = 0.2) -> None:
        """Let ``seconds`` of sim time pass."""
        self.joint_states.wait_until(self.joint_states.latest_stamp() + seconds)


def trajectory(
    start: np.ndarray, goal: np.ndarray, duration: float, joints: tuple[str, ...] = ARM, points: int = 21
) -> dict[str, Any]:
    """A smooth (minimum-jerk) FollowJointTrajectory goal from ``start`` to ``goal`` in ``duration`` s."""
    rows = []
    for t in np.linspace(0.0, duration, points):
        s = t / duration
        shape = 10 * s**3 - 15 * s**4 + 6 * s**5
        rate = (30 * s**2 - 60 * s**3 + 30 * s**4) / duration
        rows.append(
            {
                "positions": (start + (goal - start) * shape).tolist(),
                "velocities": ((goal - start) * rate).tolist(),
                "time_from_start": {"sec": round(t * 1e9) // 10**9, "nanosec": round(t * 1e9) % 10**9},
            }
        )
    return {"trajectory": {"joint_names": list(joints), "points": rows}}
