"""A gripper action controller, as ros2_control's ``position_controllers/GripperActionController``.

A ``GripperCommand`` goal sets the gripper actuator's target (lab_sim: the knuckle angle, 0 open to
0.7929 closed) and, when ``max_effort`` is positive, caps the actuator's force at it (in the actuator's
force units). The goal succeeds with ``reached_goal`` once the joint is within the goal tolerance, or
with ``stalled`` once it stops short of it (fingers closed on an object); the target stays commanded,
so a stalled gripper keeps squeezing what it holds.

All methods run on the physics thread.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any

from kinema.drivers.mujoco.execution import Execution
from kinema.drivers.mujoco.model_index import JointInfo

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class GripperSettings:
    """When a gripper goal counts as done.

    Attributes:
        goal_tolerance: position error that counts as reached (joint units).
        stall_velocity: below this speed the gripper is not moving (joint units per s).
        stall_timeout: how long it must not move, short of the goal, to count as stalled (s sim time).
    """

    goal_tolerance: float = 0.01
    stall_velocity: float = 0.01
    stall_timeout: float = 0.1


@dataclass
class _Running:
    execution: Execution
    target: float
    started: float
    still_since: float | None = None


class GripperController:
    """Serves ``GripperCommand`` goals for one position-actuated gripper joint.

    Args:
        name: the controller's name (``robotiq_gripper_controller``).
        joint: the gripper joint (with its actuator).
        model: the ``mujoco.MjModel`` (its actuator's control and force ranges are read, and the force
            range is set per goal).
        settings: goal and stall thresholds.
    """

    type_name = "position_controllers/GripperActionController"

    def __init__(self, name: str, joint: JointInfo, model: Any, settings: GripperSettings) -> None:
        assert joint.actuator is not None
        self.name = name
        self.joint = joint
        self.active = False
        self.settings = settings
        self._model = model
        self._actuator = joint.actuator
        low, high = (float(x) for x in model.actuator_ctrlrange[self._actuator])
        self._ctrl_range = (low, high) if model.actuator_ctrllimited[self._actuator] else None
        self._force_range = tuple(float(x) for x in model.actuator_forcerange[self._actuator])
        self._force_limited = bool(model.actuator_forcelimited[self._actuator])
        self._running: _Running | None = None

    @property
    def command_interfaces(self) -> list[str]:
        """``<joint>/position``."""
        return [f"{self.joint.name}/position"]

    @property
    def state_interfaces(self) -> list[str]:
        """Position and velocity of the joint."""
        return [f"{self.joint.name}/position", f"{self.joint.name}/velocity"]

    @property
    def busy(self) -> bool:
        """True while a goal runs."""
        return self._running is not None

    # -- lifecycle -------------------------------------------------------------------------------

    def activate(self, data: Any) -> None:
        """Start commanding: hold the joint where it is."""
        self.active = True
        data.ctrl[self._actuator] = self._clip(float(data.qpos[self.joint.qpos_address]))

    def deactivate(self, data: Any) -> None:
        """Stop commanding; a running goal is aborted."""
        self._end(data, "aborted", f"{self.name} was deactivated")
        self.active = False

    def on_state_reset(self, data: Any) -> None:
        """The simulation state was set from outside: abort a running goal."""
        self._end(data, "aborted", "the simulation state was reset")
        self._restore_force_limit()

    def shutdown(self, reason: str) -> None:
        """The driver stops: end a running goal without touching the simulation."""
        if self._running is not None:
            self._running.execution.finish("aborted", {})
            log.info("%s: goal aborted: %s", self.name, reason)
            self._running = None

    # -- goals -----------------------------------------------------------------------------------

    def start(self, execution: Execution, position: float, max_effort: float, data: Any) -> None:
        """Move toward ``position`` with at most ``max_effort`` (0: the actuator's own limit)."""
        if not self.active:
            log.warning("%s: goal rejected: the controller is inactive", self.name)
            execution.finish("aborted", self._state(data))
            return
        if self._running is not None:
            self._end(data, "aborted", "preempted by a newer goal")
        target = self._clip(position)
        if target != position:
            log.info("%s: target %.4f clamped to %.4f (the actuator's range)", self.name, position, target)
        self._restore_force_limit()
        if max_effort > 0.0:
            limit = max_effort
            if self._force_limited:
                limit = min(limit, max(abs(self._force_range[0]), abs(self._force_range[1])))
            self._model.actuator_forcerange[self._actuator] = (-limit, limit)
            self._model.actuator_forcelimited[self._actuator] = True
        data.ctrl[self._actuator] = target
        self._running = _Running(execution, target, float(data.time))

    def cancel(self, execution: Execution, data: Any) -> None:
        """Stop the goal of ``execution``: hold the joint where it is."""
        running = self._running
        if running is None or running.execution is not execution:
            execution.finish("canceled", {})
            return
        data.ctrl[self._actuator] = self._clip(float(data.qpos[self.joint.qpos_address]))
        self._running = None
        execution.finish("canceled", self._state(data))

    def update(self, data: Any) -> None:
        """One control period: has the gripper reached its target or stalled?"""
        running = self._running
        if running is None:
            return
        position = float(data.qpos[self.joint.qpos_address])
        if abs(position - running.target) <= self.settings.goal_tolerance:
            self._running = None
            running.execution.finish("succeeded", self._state(data, reached_goal=True))
            return
        now = float(data.time)
        if abs(float(data.qvel[self.joint.dof_address])) >= self.settings.stall_velocity:
            running.still_since = None
            return
        if running.still_since is None:
            running.still_since = now
        elif now - running.still_since >= self.settings.stall_timeout:
            self._running = None
            log.debug("%s: stalled at %.4f (target %.4f)", self.name, position, running.target)
            running.execution.finish("succeeded", self._state(data, stalled=True))

    def post_feedback(self, data: Any) -> None:
        """Post the running goal's position and effort (called at the publish rate)."""
        if self._running is not None:
            self._running.execution.post_feedback(self._state(data))

    # -- internals -------------------------------------------------------------------------------

    def _state(self, data: Any, *, reached_goal: bool = False, stalled: bool = False) -> dict[str, Any]:
        return {
            "position": float(data.qpos[self.joint.qpos_address]),
            "effort": float(data.actuator_force[self._actuator]),
            "stalled": stalled,
            "reached_goal": reached_goal,
        }

    def _end(self, data: Any, status: Any, reason: str) -> None:
        running = self._running
        if running is None:
            return
        self._running = None
        log.info("%s: goal %s: %s", self.name, status, reason)
        running.execution.finish(status, self._state(data))

    def _clip(self, value: float) -> float:
        if self._ctrl_range is None:
            return value
        return min(max(value, self._ctrl_range[0]), self._ctrl_range[1])

    def _restore_force_limit(self) -> None:
        self._model.actuator_forcerange[self._actuator] = self._force_range
        self._model.actuator_forcelimited[self._actuator] = self._force_limited
