"""Task planning: an ordered list of stages planned into one solution, MoveIt Task Constructor's way.

A :class:`Task` holds stages (:mod:`kinema.motion.task_stages`). :func:`plan_task` splits it at its
:class:`~kinema.motion.task_stages.Connect` stages into segments; each segment has at most one generator
(a state fixed on its own); the stages before the generator are planned backwards from it, those after
it forwards, and each connect joins the segment before it to the one after it with a collision-free
joint-space motion (a straight line when free, OMPL otherwise). A generator with several candidates
(:class:`~kinema.motion.task_stages.BatchPoseIK`) tries them in order of closeness to the state before.

The solution is a list of sub-trajectories, one per moving stage, each timed with toppra (at rest at both
ends, within the stage's scaled limits), each starting exactly where the one before ended. Planning fails
with a :class:`TaskPlanningError` naming the stage and why.

While it plans, each stage is ``waiting``, ``planning``, ``solved`` or ``failed`` (:data:`STAGE_STATES`);
``plan_task(..., progress=...)`` is told every change, with the seconds each stage has taken so far, so a
UI can show the task as it is planned.

Example::

    task = Task("pick", [CurrentState(q), Connect(), MoveAlongFrameAxis((0, 0, 1), "grasp_link",
                "grasp_link", 0.1, 0.1), BatchPoseIK([("world", world_T_grasp)], "grasp_link")])
    solution = plan_task(task, checker)
    trajectory = solution.joined()
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from kinema.errors import MotionError
from kinema.motion.task_stages import (
    GENERATORS,
    AllowCollisions,
    BatchPoseIK,
    CartesianMoveToJointState,
    Connect,
    CurrentState,
    FromSolution,
    MotionSettings,
    MoveAlongFrameAxis,
    PlanToJointState,
    PlanToPose,
    Stage,
    Target,
    stage_kind,
)
from kinema.motion.trajectory import JointPath, JointTrajectory

if TYPE_CHECKING:
    from kinema.motion.collision import CollisionChecker
    from kinema.motion.robot_model import RobotModel

JOIN_TOLERANCE = 1e-6  # rad or m: sub-trajectories must meet this closely
# rad or m: how far a straight line's IK may end from the joint state it moves to and still count as it
GOAL_BRANCH_TOLERANCE = 0.05
OCTOMAP_NAME = "<octomap>"  # MoveIt's collision name of the octomap
OCTOMAP_OBJECT = "octomap"  # the world object Kinema's octomap is (UpdatePlanningSceneService)


@dataclass
class Task:
    """A task being built: an id and its stages, in order."""

    task_id: str
    stages: list[Stage] = field(default_factory=list)

    def add(self, stage: Stage) -> None:
        """Append ``stage``."""
        self.stages.append(stage)


STAGE_STATES = ("waiting", "planning", "solved", "failed")


@dataclass(frozen=True)
class StageReport:
    """How a stage fares.

    Attributes:
        index: its place in the task (0-based).
        name: its name (``connect``, ``approach``).
        kind: ``generator``, ``propagator`` or ``connector``.
        status: one of :data:`STAGE_STATES`.
        comment: why it failed (``no IK solution for any of the 8 target poses: pose 3 of 8: ...``), or how
            a candidate fared; "" when there is nothing to say.
        seconds: time spent planning (and timing) it so far.
        stage_type: the stage's class (``MoveAlongFrameAxis``), MTC's stage type.
    """

    index: int
    name: str
    kind: str
    status: str
    comment: str = ""
    seconds: float = 0.0
    stage_type: str = ""


@dataclass(frozen=True, eq=False)
class SubTrajectory:
    """The timed motion of one stage, over its group's joints.

    ``stage_index`` is the stage's place in the task (-1 when unknown); the sub-trajectories of a
    replayed solution carry the index of the stage that replays them.
    """

    stage: str
    trajectory: JointTrajectory
    stage_index: int = -1


@dataclass(frozen=True)
class SceneChange:
    """A change of the collision rules between two motions of a solution.

    Attributes:
        stage: the stage that made it.
        before: how many sub-trajectories come before it.
        description: what changed, for a person (``collisions allowed: gripper - cube``).
        allowed: the pairs whose contact is allowed from here on (the rules in force after it).
        stage_index: the stage's place in the task (-1 when unknown).
    """

    stage: str
    before: int
    description: str
    allowed: frozenset[frozenset[str]] = frozenset()
    stage_index: int = -1


@dataclass(frozen=True, eq=False)
class TaskSolution:
    """A planned task.

    Attributes:
        task_id: the task's id.
        joint_names: the model's joints, the columns of ``start`` and ``end``.
        start: the full configuration the solution starts from.
        end: the full configuration it ends at.
        sub_trajectories: the stages' motions in order; each starts where the previous ended.
        reports: one per stage, all ``solved``, with the seconds each took.
        planning_seconds: how long planning took.
        scene_changes: the collision-rule changes between the motions, in order.
    """

    task_id: str
    joint_names: tuple[str, ...]
    start: np.ndarray
    end: np.ndarray
    sub_trajectories: tuple[SubTrajectory, ...]
    reports: tuple[StageReport, ...]
    planning_seconds: float = 0.0
    scene_changes: tuple[SceneChange, ...] = ()

    def tool_paths(self, model: RobotModel, frame: str) -> list[tuple[str, np.ndarray]]:
        """Where ``frame`` goes during each sub-trajectory: (stage name, positions ``(N, 3)`` in the world).

        For drawing a solution stage by stage before it runs.
        """
        from kinema.motion.kinematics import fk

        data = model.new_data()
        index = {n: i for i, n in enumerate(self.joint_names)}
        q = self.start.copy()
        paths = []
        for sub in self.sub_trajectories:
            cols = [index[n] for n in sub.trajectory.joint_names]
            points = []
            for row in sub.trajectory.positions:
                q[cols] = row
                points.append(fk(model, q, frame, data)[:3, 3])
            paths.append((sub.stage, np.array(points)))
        return paths

    def joined(self) -> JointTrajectory:
        """All sub-trajectories as one trajectory over the joints any of them moves (in model order).

        Joints a sub-trajectory does not move hold their value; each sub-trajectory starts and ends at
        rest, so the joined motion is continuous in position and velocity.

        Raises:
            MotionError: two sub-trajectories do not meet (a jump between stages).
        """
        moving = {name for sub in self.sub_trajectories for name in sub.trajectory.joint_names}
        names = tuple(n for n in self.joint_names if n in moving)
        if not names:
            names = self.joint_names
        index = {n: i for i, n in enumerate(self.joint_names)}
        cols = [index[n] for n in names]
        held = self.start.copy()
        zeros = np.zeros((1, len(cols)))
        times: list[np.ndarray] = [np.zeros(1)]
        positions: list[np.ndarray] = [held[cols][None, :]]
        velocities: list[np.ndarray] = [zeros]
        accelerations: list[np.ndarray] = [zeros]
        offset = 0.0
        previous = "the start"
        for sub in self.sub_trajectories:
            traj = sub.trajectory
            sub_cols = [index[n] for n in traj.joint_names]
            jump = float(np.abs(traj.positions[0] - held[sub_cols]).max()) if sub_cols else 0.0
            if jump > JOIN_TOLERANCE:
                raise MotionError(
                    f"task {self.task_id!r}: stage {sub.stage!r} starts {jump:.4f} rad/m away from where "
                    f"{previous} ended"
                )
            if len(traj.times) > 1:
                k = len(traj.times) - 1
                full = np.repeat(held[None, :], k, axis=0)
                full[:, sub_cols] = traj.positions[1:]
                local = [cols.index(c) for c in sub_cols]
                qd = np.zeros((k, len(cols)))
                qdd = np.zeros((k, len(cols)))
                qd[:, local] = traj.velocities[1:]
                qdd[:, local] = traj.accelerations[1:]
                times.append(offset + traj.times[1:])
                positions.append(full[:, cols])
                velocities.append(qd)
                accelerations.append(qdd)
                offset += traj.duration
                held = full[-1].copy()
            previous = f"stage {sub.stage!r}"
        return JointTrajectory(
            names,
            np.concatenate(times),
            np.concatenate(positions),
            np.concatenate(velocities),
            np.concatenate(accelerations),
        )


class TaskPlanningError(MotionError):
    """A task could not be planned: the message names the stage and why; ``reports`` has every stage."""

    def __init__(self, message: str, reports: Sequence[StageReport] = ()) -> None:
        super().__init__(message)
        self.reports = tuple(reports)


class _StageFailure(Exception):
    def __init__(self, index: int, reason: str) -> None:
        super().__init__(reason)
        self.index = index
        self.reason = reason


@dataclass
class _Piece:
    index: int
    rows: np.ndarray  # full configurations along the motion
    motion: MotionSettings
    timed: JointTrajectory | None = None  # already timed (from an earlier solution)
    change: SceneChange | None = None  # a scene change instead of a motion


class _Planner:
    def __init__(
        self,
        task: Task,
        checker: CollisionChecker,
        frames: Mapping[str, np.ndarray],
        stop: Callable[[], bool],
        progress: Callable[[tuple[StageReport, ...]], None] | None = None,
        timeout: float | None = None,
    ) -> None:
        self.task = task
        self.timeout = timeout
        self.deadline = time.monotonic() + timeout if timeout is not None else float("inf")
        self.checker = checker
        self.model: RobotModel = checker.model
        self.frames = frames
        self.stop = stop
        self.progress = progress
        self.default_padding = checker.padding
        self._free_checker: CollisionChecker | None = None
        self.status: dict[int, tuple[str, str]] = {}
        self.seconds: dict[int, float] = {}
        self.since: dict[int, float] = {}  # stage -> when its current planning began
        self.default_allowed = checker.allowed_collisions
        self.rules: list[frozenset[frozenset[str]]] = []  # stage -> the collisions allowed while planning it

    # ------------------------------------------------------------------------------ progress
    def reports(self) -> tuple[StageReport, ...]:
        now = time.monotonic()
        out = []
        for i, stage in enumerate(self.task.stages):
            status, comment = self.status.get(i, ("waiting", ""))
            seconds = self.seconds.get(i, 0.0) + (now - self.since[i] if i in self.since else 0.0)
            out.append(
                StageReport(i, stage.name, stage_kind(stage), status, comment, seconds, type(stage).__name__)
            )
        return tuple(out)

    def _tell(self) -> None:
        if self.progress is not None:
            self.progress(self.reports())

    def _stop_clock(self, index: int) -> None:
        began = self.since.pop(index, None)
        if began is not None:
            self.seconds[index] = self.seconds.get(index, 0.0) + time.monotonic() - began

    def begin(self, index: int) -> None:
        """Stage ``index`` starts planning (again, for another candidate).

        Raises:
            _StageFailure: the task's timeout ran out.
        """
        if time.monotonic() >= self.deadline:
            raise _StageFailure(index, f"the task's planning timeout of {self.timeout:.2f} s ran out")
        self.since[index] = time.monotonic()
        self.status[index] = ("planning", self.status.get(index, ("", ""))[1])
        self._tell()

    def solved(self, index: int, comment: str = "") -> None:
        self._stop_clock(index)
        self.status[index] = ("solved", comment)
        self._tell()

    def gave_up(self, index: int, comment: str) -> None:
        """Stage ``index`` failed for one candidate; it waits for the next (the comment says why)."""
        self._stop_clock(index)
        self.status[index] = ("waiting", comment)
        self._tell()

    def failed(self, index: int, reason: str) -> None:
        for running in list(self.since):
            self._stop_clock(running)
            if running != index:
                self.status[running] = ("waiting", self.status[running][1])
        self.status[index] = ("failed", reason)
        self._tell()

    def add_seconds(self, index: int, seconds: float) -> None:
        self.seconds[index] = self.seconds.get(index, 0.0) + seconds

    # ----------------------------------------------------------------------------------- helpers
    def label(self, index: int) -> str:
        if not self.task.stages:
            return "the task"
        stage = self.task.stages[index]
        return f"stage {index + 1} of {len(self.task.stages)} ({stage.name!r})"

    def check(self, index: int, padding: float, ignore_environment: bool = False) -> CollisionChecker:
        """The checker for stage ``index``: its padding, and the collisions allowed where it stands."""
        if ignore_environment:
            if self._free_checker is None:
                from kinema.motion.collision import CollisionChecker

                self._free_checker = CollisionChecker(self.model, None, padding=padding)
            self._free_checker.padding = padding
            self._free_checker.allowed_collisions = self.rules[index]
            return self._free_checker
        self.checker.padding = padding
        self.checker.allowed_collisions = self.rules[index]
        return self.checker

    def resolve_rules(self) -> None:
        """The collisions allowed at each stage: the defaults, changed by each AllowCollisions before it."""
        allowed = set(self.default_allowed)
        for index, stage in enumerate(self.task.stages):
            self.rules.append(frozenset(allowed))
            if isinstance(stage, AllowCollisions):
                pairs = {
                    frozenset((a, b))
                    for a in self.names(index, stage.first)
                    for b in self.names(index, stage.second)
                    if a != b
                }
                allowed = allowed | pairs if stage.allow else allowed - pairs

    def names(self, index: int, names: Sequence[str]) -> list[str]:
        """Robot links and scene object names that ``names`` (links, SRDF groups, object ids, attached
        objects, MoveIt's ``<octomap>``) stand for."""
        from kinema.errors import did_you_mean

        scene = self.checker.scene
        out: list[str] = []
        for name in names:
            if name in self.model.link_names or name in scene.objects:
                out.append(name)
            elif scene.shape_names(name):
                out.extend(scene.shape_names(name))
            elif name == OCTOMAP_NAME:
                # MoveIt's name of the octomap; Kinema's is the world object UpdatePlanningSceneService
                # fills. Without one there is nothing to allow or forbid, as in MoveIt.
                out.extend(scene.shape_names(OCTOMAP_OBJECT))
            elif name in self.model.semantic.groups and self.model.semantic.groups[name].links:
                out.extend(self.model.semantic.groups[name].links)
            else:
                known = [
                    *self.model.link_names,
                    *scene.world,
                    *scene.attached,
                    *scene.objects,
                    *self.model.semantic.groups,
                ]
                raise _StageFailure(
                    index,
                    f"{name!r} is no robot link, planning group listing its links, or planning-scene "
                    f"object; {did_you_mean(name, known)}",
                )
        return out

    def piece(self, index: int, rows: np.ndarray) -> _Piece:
        stage = self.task.stages[index]
        if isinstance(stage, AllowCollisions):
            after = self.rules[index + 1] if index + 1 < len(self.rules) else self.rules[index]
            change = SceneChange(stage.name, 0, stage.describe(), after)
            return _Piece(index, rows, MotionSettings(), change=change)
        assert not isinstance(stage, GENERATORS), "a generator's rows come with its solutions"
        return _Piece(index, rows, stage.motion)

    def world_T(self, target: Target, q: np.ndarray) -> np.ndarray:
        from kinema.motion.frames import FrameTree

        frame, pose = target
        return FrameTree(self.model, q, self.frames).world_T(frame) @ np.asarray(pose, dtype=float)

    def group(self, index: int, name: str):
        if name not in self.model.groups:
            from kinema.errors import did_you_mean

            raise _StageFailure(
                index, f"unknown planning group {name!r}; {did_you_mean(name, list(self.model.groups))}"
            )
        return self.model.group(name)

    # ---------------------------------------------------------------------------------- stages
    def generate(
        self, index: int, before: np.ndarray | None
    ) -> list[tuple[np.ndarray, np.ndarray, list[_Piece]]]:
        """Candidates of a generator: (start state, end state, its own pieces)."""
        stage = self.task.stages[index]
        self.begin(index)
        if isinstance(stage, CurrentState):
            q = np.asarray(stage.state, dtype=float)
            if q.shape != (len(self.model.joint_names),):
                raise _StageFailure(index, f"the state must have {len(self.model.joint_names)} joint values")
            return [(q, q, [])]
        if isinstance(stage, FromSolution):
            solution = stage.solution
            if tuple(solution.joint_names) != tuple(self.model.joint_names):
                raise _StageFailure(index, "the solution was planned for another robot model")
            pieces = []
            for k, sub in enumerate([*solution.sub_trajectories, None]):
                pieces += [
                    _Piece(index, np.array([solution.start]), MotionSettings(), change=change)
                    for change in solution.scene_changes
                    if change.before == k
                ]
                if sub is not None:
                    pieces.append(_Piece(index, np.array([solution.start]), MotionSettings(), sub.trajectory))
            return [(solution.start.copy(), solution.end.copy(), pieces)]
        assert isinstance(stage, BatchPoseIK)
        return self.batch_ik(index, stage, before)

    def batch_ik(
        self, index: int, stage: BatchPoseIK, before: np.ndarray | None
    ) -> list[tuple[np.ndarray, np.ndarray, list[_Piece]]]:
        from kinema.motion.inverse_kinematics import IkOptions, ik

        if before is None:
            raise _StageFailure(
                index, "batch pose IK needs a state before it to solve from (a current state)"
            )
        self.group(index, stage.group)
        checker = self.check(index, stage.link_padding)
        options = IkOptions(attempts=stage.ik_attempts, rng_seed=stage.seed)
        found: list[np.ndarray] = []
        reasons: list[str] = []
        n = len(stage.targets)
        for i, target in enumerate(stage.targets):
            try:
                world_T_target = self.world_T(target, before)
                q = ik(
                    self.model,
                    world_T_target,
                    before,
                    stage.group,
                    stage.ik_frame,
                    options=options,
                    accept=checker.is_valid,
                )
            except MotionError as error:
                reasons.append(f"pose {i + 1} of {n}: {error}")
                continue
            found.append(q)
        if not found:
            raise _StageFailure(
                index, f"no IK solution for any of the {n} target poses: " + "; ".join(reasons)
            )
        found.sort(key=lambda q: float(np.linalg.norm(q - before)))
        return [(q, q, []) for q in found[: stage.max_ik_solutions]]

    def forward(self, index: int, q_from: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Plan a propagator from ``q_from``: (rows, end state)."""
        stage = self.task.stages[index]
        self.begin(index)
        if isinstance(stage, AllowCollisions):
            return q_from[None, :].copy(), q_from
        try:
            if isinstance(stage, MoveAlongFrameAxis):
                return self.along_axis(index, stage, q_from, backwards=False)
            if isinstance(stage, PlanToJointState):
                goal = self.group_goal(index, stage.motion.group, stage.goal)
                return self.joint_motion(index, stage.motion, q_from, goal)
            if isinstance(stage, PlanToPose):
                return self.plan_to_pose(index, stage, q_from)
            if isinstance(stage, CartesianMoveToJointState):
                return self.cartesian_to_joint_state(index, stage, q_from)
        except MotionError as error:
            raise _StageFailure(index, str(error)) from error
        raise _StageFailure(index, f"a {type(stage).__name__} stage cannot follow a state here")

    def backward(self, index: int, q_to: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Plan a propagator that must end at ``q_to``: (rows, start state)."""
        stage = self.task.stages[index]
        self.begin(index)
        if isinstance(stage, AllowCollisions):
            return q_to[None, :].copy(), q_to
        if not isinstance(stage, MoveAlongFrameAxis):
            raise _StageFailure(
                index,
                f"{stage.name!r} plans forwards only, but a state-fixing stage follows it; put a connect "
                "stage between them, or move it after that stage",
            )
        try:
            return self.along_axis(index, stage, q_to, backwards=True)
        except MotionError as error:
            raise _StageFailure(index, str(error)) from error

    def joint_motion(
        self, index: int, motion: MotionSettings, q_from: np.ndarray, goal: Mapping[str, float] | np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        from kinema.motion.planner import PlanningOptions, plan_joint_goal

        g = self.group(index, motion.group)
        checker = self.check(index, motion.link_padding)
        # The search gets its own planning time, or what is left of the task's timeout when that is less.
        left = self.deadline - time.monotonic()
        if left <= 0:
            raise _StageFailure(index, f"the task's planning timeout of {self.timeout:.2f} s ran out")
        path = plan_joint_goal(
            checker,
            q_from,
            goal,
            motion.group,
            PlanningOptions(
                timeout=min(motion.planning_time, left),
                seed=motion.seed,
                max_iterations=motion.max_iterations,
            ),
        )
        rows = np.repeat(q_from[None, :], len(path.positions), axis=0)
        rows[:, list(g.indices)] = path.positions
        return rows, rows[-1].copy()

    def plan_to_pose(
        self, index: int, stage: PlanToPose, q_from: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """IK for the target, then a free motion there; with orientation constraints, a motion that keeps
        them (the free one when it does, else a straight Cartesian line)."""
        from kinema.motion.cartesian import plan_cartesian_path
        from kinema.motion.inverse_kinematics import IkOptions, ik
        from kinema.motion.orientation_constraints import OrientationKeeper

        self.group(index, stage.motion.group)
        checker = self.check(index, stage.motion.link_padding)
        world_T_target = self.world_T(stage.target, q_from)
        keeper = OrientationKeeper(self.model, q_from, stage.orientation_constraints)
        goal_problem = keeper.target_problem(world_T_target, stage.ik_frame)
        if goal_problem:
            raise MotionError(goal_problem)
        q_goal = ik(
            self.model,
            world_T_target,
            q_from,
            stage.motion.group,
            stage.ik_frame,
            options=IkOptions(attempts=stage.ik_attempts, rng_seed=stage.motion.seed),
            accept=lambda q: checker.is_valid(q) and not keeper.violation(q[None, :]),
        )
        rows, end = self.joint_motion(index, stage.motion, q_from, q_goal)
        free_problem = keeper.violation(rows)
        if not free_problem:
            return rows, end
        # The free motion turns the link too far: a straight line of the IK frame turns it steadily from
        # the start orientation to the target's, both of which keep the constraints.
        result = plan_cartesian_path(checker, q_from, [world_T_target], stage.motion.group, stage.ik_frame)
        if result.fraction < 1.0 - 1e-9:
            why = f" ({result.reason})" if result.reason else ""
            raise MotionError(
                f"the free motion breaks the orientation constraint ({free_problem}), and a straight line to "
                f"the target stopped at {100 * result.fraction:.0f} %{why}"
            )
        g = self.model.group(stage.motion.group)
        line = np.repeat(q_from[None, :], len(result.path.positions), axis=0)
        line[:, list(g.indices)] = result.path.positions
        line_problem = keeper.violation(line)
        if line_problem:
            raise MotionError(
                f"no motion keeps the orientation constraint: neither the free motion ({free_problem}) "
                f"nor a straight line ({line_problem})"
            )
        return line, line[-1].copy()

    def group_goal(self, index: int, group: str, goal: Mapping[str, float]) -> dict[str, float]:
        """The positions of ``goal`` (a joint state, perhaps a whole saved robot state) for ``group``'s
        joints: the robot's other joints (a gripper, its mimic fingers) are left where they are, as MTC's
        stages read a robot-state goal; a name the robot does not have is an error.

        Raises:
            MotionError: an unknown joint (with the close names), or no joint of the group.
        """
        model = self.model
        g = self.group(index, group)
        for name in goal:
            if name not in model.joint_names and name not in model.mimics:
                from kinema.errors import did_you_mean

                raise MotionError(
                    f"the joint state names unknown joint {name!r}; "
                    f"{did_you_mean(name, model.joint_names, limit=32)}"
                )
        mine = {n: float(v) for n, v in goal.items() if n in g.joint_names}
        if not mine:
            raise MotionError(
                f"the joint state names no joint of planning group {group!r} ({', '.join(g.joint_names)})"
            )
        return mine

    def cartesian_to_joint_state(
        self, index: int, stage: CartesianMoveToJointState, q_from: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """A straight line of the tip to where ``stage.goal`` puts it, ending exactly at the goal."""
        from kinema.motion.cartesian import plan_cartesian_path
        from kinema.motion.kinematics import fk
        from kinema.motion.planner import goal_configuration

        g = self.group(index, stage.motion.group)
        goal = self.group_goal(index, stage.motion.group, stage.goal)
        tip = stage.tip_frame or g.tip_link
        if not tip:
            raise MotionError(
                f"planning group {stage.motion.group!r} has no tip link (the SRDF gives it no chain)"
            )
        checker = self.check(index, stage.motion.link_padding)
        q_goal = goal_configuration(checker, q_from, goal, stage.motion.group)
        cols = list(g.indices)
        if np.abs(q_goal[cols] - q_from[cols]).max() <= JOIN_TOLERANCE:
            return np.vstack([q_from, q_goal]), q_goal
        result = plan_cartesian_path(checker, q_from, [fk(self.model, q_goal, tip)], stage.motion.group, tip)
        if result.fraction < 1.0 - 1e-9:
            why = f": {result.reason}" if result.reason else ""
            raise MotionError(
                f"the straight line of {tip} to the joint state stopped at {100 * result.fraction:.0f} %{why}"
            )
        rows = np.repeat(q_from[None, :], len(result.path.positions), axis=0)
        rows[:, cols] = result.path.positions
        off = q_goal[cols] - rows[-1, cols]
        worst = int(np.argmax(np.abs(off)))
        if abs(off[worst]) > GOAL_BRANCH_TOLERANCE:
            raise MotionError(
                f"the straight line brings {tip} where the joint state puts it, but in another joint "
                f"configuration ({g.joint_names[worst]} {rows[-1, cols][worst]:.3f}, not "
                f"{q_goal[cols][worst]:.3f} rad); plan to the joint state instead"
            )
        # Spread the last few milliradians along the motion rather than jumping at its end.
        rows[:, cols] += np.linspace(0.0, 1.0, len(rows))[:, None] * off[None, :]
        bad = next((k for k, row in enumerate(rows) if not checker.is_valid(row)), None)
        if bad is not None:
            raise MotionError(f"the straight line of {tip} collides at {100 * bad / (len(rows) - 1):.0f} %")
        if len(rows) < 2:
            rows = np.vstack([q_from, q_goal])
        rows[-1] = q_goal
        return rows, q_goal

    def along_axis(
        self, index: int, stage: MoveAlongFrameAxis, q: np.ndarray, *, backwards: bool
    ) -> tuple[np.ndarray, np.ndarray]:
        from kinema.motion.cartesian import plan_cartesian_path
        from kinema.motion.kinematics import fk

        g = self.group(index, stage.motion.group)
        world_T_axis = self.world_T((stage.axis_frame, np.eye(4)), q)
        axis = np.asarray(stage.axis, dtype=float)
        direction = world_T_axis[:3, :3] @ (axis / np.linalg.norm(axis))
        hand = fk(self.model, q, stage.hand_frame)
        target = hand.copy()
        sign = -1.0 if backwards else 1.0
        target[:3, 3] += sign * stage.max_distance * direction
        checker = self.check(index, stage.motion.link_padding, stage.ignore_environment_collisions)
        result = plan_cartesian_path(checker, q, [target], stage.motion.group, stage.hand_frame)
        reached = result.fraction * stage.max_distance
        if reached < stage.min_distance - 1e-4:
            why = f": {result.reason}" if result.reason else ""
            raise _StageFailure(
                index,
                f"Cartesian path stopped at {100 * result.fraction:.0f} % ({reached:.3f} m of "
                f"{stage.max_distance:.3f} m; at least {stage.min_distance:.3f} m needed){why}",
            )
        rows = np.repeat(q[None, :], len(result.path.positions), axis=0)
        rows[:, list(g.indices)] = result.path.positions
        if backwards:
            rows = rows[::-1].copy()
            return rows, rows[0].copy()
        return rows, rows[-1].copy()

    # ---------------------------------------------------------------------------------- the task
    def segments(self) -> list[tuple[int | None, list[int]]]:
        """(index of the connect before, indices of the segment's stages)."""
        out: list[tuple[int | None, list[int]]] = [(None, [])]
        for i, stage in enumerate(self.task.stages):
            if isinstance(stage, Connect):
                out.append((i, []))
            else:
                out[-1][1].append(i)
        return out

    def plan_segment(
        self, members: list[int], before: np.ndarray | None
    ) -> tuple[np.ndarray, np.ndarray, list[_Piece]]:
        """Plan one segment: (start state, end state, pieces)."""
        generators = [i for i in members if isinstance(self.task.stages[i], GENERATORS)]
        if len(generators) > 1:
            raise _StageFailure(
                generators[1],
                f"it fixes a state, but {self.task.stages[generators[0]].name!r} already did without a "
                "connect stage between them",
            )
        if not generators:
            if before is None:
                raise _StageFailure(
                    members[0] if members else 0, "a task starts with a state: a current state or a solution"
                )
            return self.propagate(members, [], before)
        g = generators[0]
        failures: list[_StageFailure] = []
        candidates = self.generate(g, before)
        self.solved(g, f"{len(candidates)} solutions" if len(candidates) > 1 else "")
        for k, (start, end, own) in enumerate(candidates, start=1):
            try:
                pieces: list[_Piece] = []
                q = start
                for i in reversed([m for m in members if m < g]):
                    rows, q = self.backward(i, q)
                    pieces.insert(0, self.piece(i, rows))
                    self.solved(i)
                first = q
                _, last, after = self.propagate([m for m in members if m > g], [], end)
                if len(candidates) > 1:
                    self.status[g] = ("solved", f"solution {k} of {len(candidates)} used")
                    self._tell()
                return first, last, pieces + own + after
            except _StageFailure as failure:
                failures.append(failure)
                if len(candidates) > 1:
                    self.gave_up(
                        failure.index,
                        f"with solution {k} of {len(candidates)} of {self.task.stages[g].name!r}: "
                        f"{failure.reason}",
                    )
                if self.stop() or time.monotonic() >= self.deadline:
                    break
        if len(failures) == 1:
            raise failures[0]
        worst = failures[0]
        raise _StageFailure(
            worst.index,
            f"{worst.reason} (each of the {len(failures)} solutions of {self.task.stages[g].name!r} failed "
            "here or later)",
        )

    def propagate(
        self, members: list[int], pieces: list[_Piece], q: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, list[_Piece]]:
        start = q
        for i in members:
            rows, q = self.forward(i, q)
            pieces.append(self.piece(i, rows))
            self.solved(i)
        return start, q, pieces

    def connect(self, index: int, q_from: np.ndarray, q_to: np.ndarray) -> _Piece:
        stage = self.task.stages[index]
        assert isinstance(stage, Connect)
        self.begin(index)
        g = self.group(index, stage.motion.group)
        others = [i for i in range(len(q_from)) if i not in set(g.indices)]
        differ = [self.model.joint_names[i] for i in others if abs(q_from[i] - q_to[i]) > JOIN_TOLERANCE]
        if differ:
            raise _StageFailure(
                index,
                f"the states before and after differ in joints outside group {stage.motion.group!r}: "
                f"{', '.join(differ)}",
            )
        try:
            rows, _ = self.joint_motion(index, stage.motion, q_from, q_to)
        except MotionError as error:
            raise _StageFailure(index, str(error)) from error
        self.solved(index)
        return _Piece(index, rows, stage.motion)

    def run(self) -> tuple[np.ndarray, np.ndarray, list[_Piece]]:
        if not self.task.stages:
            raise _StageFailure(0, "the task has no stages")
        self.resolve_rules()
        start: np.ndarray | None = None
        end: np.ndarray | None = None
        pieces: list[_Piece] = []
        for connect, members in self.segments():
            if self.stop():
                raise _StageFailure(members[0] if members else connect or 0, "planning was stopped")
            if connect is not None and not members:
                raise _StageFailure(connect, "a connect needs a stage after it to connect to")
            if connect is not None and end is None:
                raise _StageFailure(connect, "a connect needs a state before it (a current state first)")
            seg_start, seg_end, seg_pieces = self.plan_segment(members, end)
            if connect is not None:
                assert end is not None
                pieces.append(self.connect(connect, end, seg_start))
            elif end is not None and np.abs(seg_start - end).max() > JOIN_TOLERANCE:
                raise _StageFailure(members[0], "it starts away from where the stage before ended")
            if start is None:
                start = seg_start
            pieces.extend(seg_pieces)
            end = seg_end
        assert start is not None and end is not None
        return start, end, pieces


def plan_task(
    task: Task,
    checker: CollisionChecker,
    *,
    frames: Mapping[str, np.ndarray] | None = None,
    stop: Callable[[], bool] | None = None,
    progress: Callable[[tuple[StageReport, ...]], None] | None = None,
    timeout: float | None = None,
) -> TaskSolution:
    """Plan ``task`` into a solution against ``checker``'s planning scene.

    Args:
        task: the stages, in order.
        checker: collision checker (robot model and planning scene); its padding is the default for
            stages without their own, and is restored afterwards.
        frames: named fixed frames (objects, cameras) target poses may be given in, besides the robot's
            links and ``world``.
        stop: called between steps; planning stops with an error when it returns True.
        progress: called (on the planning thread) whenever a stage's state changes, with every stage's
            report; it must not block.
        timeout: seconds the whole task may take (MTC's task timeout): no stage starts after it, and a
            search for a collision-free motion gets at most what is left of it.

    Raises:
        TaskPlanningError: naming the stage that failed and why; ``reports`` holds every stage's status.
    """
    from kinema.motion.timing import time_parameterize

    began = time.monotonic()
    planner = _Planner(task, checker, frames or {}, stop or (lambda: False), progress, timeout)
    padding = checker.padding
    try:
        start, end, pieces = planner.run()
        subs: list[SubTrajectory] = []
        changes: list[SceneChange] = []
        for piece in pieces:
            stage = task.stages[piece.index]
            if piece.change is not None:
                changes.append(replace(piece.change, before=len(subs), stage_index=piece.index))
                continue
            if piece.timed is not None:
                subs.append(SubTrajectory(stage.name, piece.timed, piece.index))
                continue
            g = planner.model.group(piece.motion.group)
            path = JointPath(g.joint_names, piece.rows[:, list(g.indices)])
            timing_began = time.monotonic()
            try:
                trajectory = time_parameterize(
                    path,
                    planner.model,
                    piece.motion.velocity_scale,
                    piece.motion.acceleration_scale,
                    sample_period=piece.motion.sample_period,
                )
            except MotionError as error:
                raise _StageFailure(piece.index, f"timing failed: {error}") from error
            planner.add_seconds(piece.index, time.monotonic() - timing_began)
            subs.append(SubTrajectory(stage.name, trajectory, piece.index))
    except _StageFailure as failure:
        planner.failed(failure.index, failure.reason)
        reports = planner.reports()
        raise TaskPlanningError(
            f"task {task.task_id!r}: {planner.label(failure.index)} failed: {failure.reason}", reports
        ) from None
    finally:
        checker.padding = padding
        checker.allowed_collisions = planner.default_allowed
    solution = TaskSolution(
        task.task_id,
        tuple(planner.model.joint_names),
        start,
        end,
        tuple(subs),
        planner.reports(),
        time.monotonic() - began,
        tuple(changes),
    )
    solution.joined()  # proves the sub-trajectories meet
    return solution
