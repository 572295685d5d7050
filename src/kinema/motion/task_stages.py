"""The stages a task is built from: what each asks for, as plain data (planning is in :mod:`.task`).

A task (MoveIt Task Constructor's model, which MoveIt Pro's MTC behaviors use) is an ordered list of
stages. Three kinds:

- **generators** fix a robot state on their own: :class:`CurrentState`, :class:`BatchPoseIK` (the IK
  solution of one of several candidate poses) and :class:`FromSolution` (an earlier solution, replayed);
- **propagators** move from the state before them (or, when a generator follows them, back from the
  state after them): :class:`MoveAlongFrameAxis` always; :class:`PlanToJointState`, :class:`PlanToPose`
  and :class:`CartesianMoveToJointState` only forwards;
- **connectors** (:class:`Connect`) join the state before them to the state after them with a
  collision-free joint-space motion;
- **scene changes** (:class:`AllowCollisions`) move nothing: they change the collision rules of the
  stages after them (a gripper may touch the object it grasps), and the solution records them between
  its motions.

Poses are ``(frame, frame_T_pose)`` pairs: the frame (``world``, a robot link such as ``grasp_link``, or
another named frame) is resolved when the task is planned, at the state the stage starts from.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from kinema.errors import MotionError

if TYPE_CHECKING:
    from kinema.motion.task import TaskSolution

Target = tuple[str, np.ndarray]


@dataclass(frozen=True)
class MotionSettings:
    """How a stage's motion is planned and timed.

    Attributes:
        group: the planning group that moves.
        velocity_scale: fraction of the joints' velocity limits, (0, 1].
        acceleration_scale: fraction of the joints' acceleration limits, (0, 1].
        link_padding: clearance (m) kept between the robot and the planning scene.
        sample_period: spacing of the timed trajectory's points, seconds.
        planning_time: seconds the search may take when a straight joint-space move collides.
        seed: random seed of the IK restarts and of the collision-free search (Kinema's seeded RRT-Connect):
            the same task, scene and seed give the same solution in any process.
        max_iterations: samples the collision-free search draws before the stage fails.
    """

    group: str = ""  # the planning group that moves: behaviors pass the config's; "" is refused when it plans
    velocity_scale: float = 1.0
    acceleration_scale: float = 1.0
    link_padding: float = 0.01
    sample_period: float = 0.01
    planning_time: float = 1.0
    seed: int = 0
    max_iterations: int = 5000

    def __post_init__(self) -> None:
        for label, value in (("velocity", self.velocity_scale), ("acceleration", self.acceleration_scale)):
            if not 0.0 < value <= 1.0:
                raise MotionError(f"{label} scale factor must be in (0, 1], got {value}")
        if not np.isfinite(self.link_padding) or self.link_padding < 0:
            raise MotionError(f"link padding must be a non-negative distance (m), got {self.link_padding}")
        if not self.sample_period > 0:
            raise MotionError(f"the trajectory's sample period must be positive, got {self.sample_period} s")
        if not self.planning_time > 0:
            raise MotionError(f"planning time must be positive, got {self.planning_time} s")
        if self.max_iterations < 1:
            raise MotionError(f"max_iterations must be at least 1, got {self.max_iterations}")


@dataclass(frozen=True, eq=False)
class CurrentState:
    """Generator: the robot's state when the task is planned (a configuration over the model's joints)."""

    state: np.ndarray
    name: str = "current state"


@dataclass(frozen=True, eq=False)
class FromSolution:
    """Generator: replay an earlier solution's motions; the task goes on from where it ended."""

    solution: TaskSolution
    name: str = "from solution"


@dataclass(frozen=True, eq=False)
class PlanToJointState:
    """Propagator (forwards only): plan from the state before to ``goal`` (joint name -> position)."""

    goal: Mapping[str, float]
    motion: MotionSettings = field(default_factory=MotionSettings)
    name: str = "plan to joint state"


@dataclass(frozen=True)
class OrientationConstraint:
    """Keep ``link`` turned at most ``angle_tolerance`` (rad) from its orientation where the stage starts.

    The angle is that of the rotation between the two orientations (about any axis), so 0.2 lets the
    link tilt or twist by up to 0.2 rad along the whole motion, its end included.
    """

    link: str
    angle_tolerance: float

    def __post_init__(self) -> None:
        if not np.isfinite(self.angle_tolerance) or self.angle_tolerance < 0:
            raise MotionError(
                f"orientation constraint on {self.link!r}: angle_tolerance must be a non-negative angle "
                f"(rad), got {self.angle_tolerance}"
            )


@dataclass(frozen=True, eq=False)
class PlanToPose:
    """Propagator (forwards only): put ``ik_frame`` at ``target`` (IK from several seeds, then OMPL).

    With ``orientation_constraints`` the goal must keep each constrained link within its tolerance, and
    so must the motion: the free motion is used when it does, else a straight Cartesian line of
    ``ik_frame`` (which turns it steadily from the start orientation to the target's); the stage fails
    naming the link and the angle reached when neither does.
    """

    target: Target
    ik_frame: str
    motion: MotionSettings = field(default_factory=MotionSettings)
    ik_attempts: int = 20
    name: str = "plan to pose"
    orientation_constraints: Sequence[OrientationConstraint] = ()


@dataclass(frozen=True, eq=False)
class CartesianMoveToJointState:
    """Propagator (forwards only): move the tip of the group in a straight line to where ``goal`` puts it,
    ending at ``goal`` (joint name -> position).

    The tip is ``tip_frame``, or the group's tip link. Goal joints outside the group are left where they
    are. The straight line must be followed all the way, and reach the goal's own joint configuration (not
    another IK branch with the same tip pose); the few milliradians the line's IK ends away from it are
    spread along the motion so it ends exactly at ``goal``.
    """

    goal: Mapping[str, float]
    motion: MotionSettings = field(default_factory=lambda: MotionSettings(link_padding=0.0))
    tip_frame: str | None = None
    name: str = "cartesian move to joint state"


@dataclass(frozen=True, eq=False)
class Connect:
    """Connector: a collision-free joint-space motion from the state before to the state after."""

    motion: MotionSettings = field(default_factory=MotionSettings)
    name: str = "connect"


@dataclass(frozen=True, eq=False)
class MoveAlongFrameAxis:
    """Propagator: move ``hand_frame`` in a straight line along ``axis`` of ``axis_frame``.

    It moves ``max_distance`` when it can and fails when less than ``min_distance`` is reachable. Planned
    backwards (a generator follows it, as an approach before a grasp) it ends at that generator's state.
    """

    axis: Sequence[float]
    axis_frame: str
    hand_frame: str
    min_distance: float
    max_distance: float
    motion: MotionSettings = field(default_factory=lambda: MotionSettings(link_padding=0.0))
    ignore_environment_collisions: bool = False
    name: str = "move along frame axis"

    def __post_init__(self) -> None:
        axis = np.asarray(self.axis, dtype=float)
        if axis.shape != (3,) or not np.all(np.isfinite(axis)) or np.linalg.norm(axis) < 1e-9:
            raise MotionError(
                f"{self.name}: the axis must be 3 finite numbers, not all zero; got {self.axis}"
            )
        if not (0 <= self.min_distance <= self.max_distance) or not np.isfinite(self.max_distance):
            raise MotionError(
                f"{self.name}: distances must satisfy 0 <= min_distance <= max_distance; got "
                f"min {self.min_distance}, max {self.max_distance}"
            )


@dataclass(frozen=True, eq=False)
class BatchPoseIK:
    """Generator: of the candidate ``targets`` for ``ik_frame``, the IK solution closest to the state before.

    ``max_ik_solutions`` bounds how many solutions (in order of closeness) later stages may try before the
    task fails.
    """

    targets: Sequence[Target]
    ik_frame: str
    group: str = ""  # the planning group that moves: behaviors pass the config's; "" is refused when it plans
    max_ik_solutions: int = 4
    ik_attempts: int = 20
    seed: int = 0
    link_padding: float = 0.0
    name: str = "batch pose IK"

    def __post_init__(self) -> None:
        if not self.targets:
            raise MotionError(f"{self.name}: no target poses to solve IK for")
        if self.max_ik_solutions < 1:
            raise MotionError(
                f"{self.name}: max_ik_solutions must be at least 1, got {self.max_ik_solutions}"
            )


@dataclass(frozen=True, eq=False)
class AllowCollisions:
    """Scene change: contacts between ``first`` and ``second`` are allowed (or, with ``allow=False``,
    checked again) in the stages after this one.

    Names are robot links, planning groups that list their links in the SRDF (``gripper`` on lab_sim),
    or planning-scene objects (an object's id stands for all its shapes).
    """

    first: Sequence[str]
    second: Sequence[str]
    allow: bool = True
    name: str = "allow collisions"

    def __post_init__(self) -> None:
        if not self.first or not self.second:
            raise MotionError(f"{self.name}: name what may touch what: both sides need at least one name")

    def describe(self) -> str:
        """One line for a person: ``collisions allowed: gripper - cube``."""
        verb = "allowed" if self.allow else "checked again"
        return f"collisions {verb}: {', '.join(self.first)} - {', '.join(self.second)}"


Stage = (
    CurrentState
    | FromSolution
    | PlanToJointState
    | PlanToPose
    | CartesianMoveToJointState
    | Connect
    | MoveAlongFrameAxis
    | BatchPoseIK
    | AllowCollisions
)

GENERATORS = (CurrentState, FromSolution, BatchPoseIK)


def stage_kind(stage: Stage) -> str:
    """A short word for the stage's role: ``generator``, ``propagator``, ``connector`` or ``scene``."""
    if isinstance(stage, GENERATORS):
        return "generator"
    if isinstance(stage, AllowCollisions):
        return "scene"
    return "connector" if isinstance(stage, Connect) else "propagator"
