"""Joint-space motion planning: a straight joint-space move when it is collision-free, OMPL otherwise.

Trying the straight line first makes waypoint moves predictable (the same start and goal give the same
motion every time, as an operator expects) and fast; OMPL (RRTConnect by default) handles the cases where
something is in the way, and its path is shortened by OMPL's path simplifier.
"""

from __future__ import annotations

import threading
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from kinema.errors import MotionError, did_you_mean
from kinema.motion.collision import CollisionChecker
from kinema.motion.trajectory import JointPath

PLANNERS = ("RRTConnect", "RRT", "RRTstar", "BKPIECE1", "KPIECE1", "LBKPIECE1", "PRM", "BITstar", "AORRTC")
_OMPL_LOCK = threading.Lock()  # OMPL's RNG and log settings are process-global
_ompl_ready = False


@dataclass(frozen=True)
class PlanningOptions:
    """Tuning of :func:`plan_joint_goal`.

    Attributes:
        planner: OMPL geometric planner name (one of ``PLANNERS``).
        timeout: seconds the planner may search before giving up.
        simplify_timeout: seconds for path simplification.
        max_step: collision-check resolution: largest joint change (rad or m) between checked states.
        try_direct: first try the straight joint-space line from start to goal.
        limit_tolerance: how far (rad or m) the start may lie outside the limits and still be clamped in
            (joint encoders report values a hair outside).
        fix_start_collision: a start state in collision (a gripper resting on the table after a press,
            within the link padding of what it holds) is left for the nearest collision-free state found
            by sampling around it, as MoveIt's FixStartStateCollision planning adapter does; the path
            then begins with that short move. False: such a start is an error.
        start_jiggle_fraction: the largest move tried, as a fraction of each joint's range (MoveIt's
            ``jiggle_fraction``, whose 0.05 would let the tool jump ~15 cm; 0.01 is ~3 cm, enough to leave
            a contact inside the link padding); smaller moves are tried first.
        seed: None: search with OMPL, whose random generator is process-wide (the same request may take
            another path later in the same process). A number: search with Kinema's seeded RRT-Connect
            (:mod:`kinema.motion.rrt`), which gives the same path for the same request and seed in any
            process; ``planner`` must then be ``"RRTConnect"``.
        max_iterations: the seeded search's sample cap (OMPL's planners are bounded by ``timeout`` only).
    """

    planner: str = "RRTConnect"
    timeout: float = 1.0
    simplify_timeout: float = 0.1
    max_step: float = 0.02
    try_direct: bool = True
    limit_tolerance: float = 1e-2
    fix_start_collision: bool = True
    start_jiggle_fraction: float = 0.01
    seed: int | None = None
    max_iterations: int = 5000


def _ompl():
    global _ompl_ready
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    if not _ompl_ready:
        ou.setLogLevel(ou.LogLevel.LOG_WARN)  # the default logs on every solve
        ou.RNG.setSeed(1)  # once per process: OMPL ignores later seeds
        _ompl_ready = True
    return ob, og, ou


def goal_configuration(
    checker: CollisionChecker, start: np.ndarray, goal: Mapping[str, float], group: str
) -> np.ndarray:
    """Apply a joint goal by name to ``start``; every named joint must belong to ``group``.

    Raises:
        MotionError: unknown joint names (listing the valid ones), joints outside the group, or a goal
            outside the joint limits.
    """
    model = checker.model
    g = model.group(group)
    q = np.array(start, dtype=float)
    for name, value in goal.items():
        if name not in model.joint_names:
            raise MotionError(
                f"goal names unknown joint {name!r}; {did_you_mean(name, model.joint_names, limit=32)}"
            )
        if name not in g.joint_names:
            raise MotionError(
                f"goal joint {name!r} is not in planning group {group!r} (joints: {', '.join(g.joint_names)})"
            )
        i = model.index(name)
        value = float(value)
        if not model.lower[i] - 1e-6 <= value <= model.upper[i] + 1e-6:
            raise MotionError(
                f"goal {name} = {value:.4f} is outside its limits "
                f"[{model.lower[i]:.4f}, {model.upper[i]:.4f}]"
            )
        q[i] = min(max(value, model.lower[i]), model.upper[i])
    return q


def plan_joint_goal(
    checker: CollisionChecker,
    start: np.ndarray,
    goal: Mapping[str, float] | np.ndarray,
    group: str,
    options: PlanningOptions | None = None,
) -> JointPath:
    """Plan a collision-free joint-space path for ``group`` from ``start`` to ``goal``.

    Joints outside the group keep their ``start`` values (the gripper opening, say), and the checker's
    padding applies between the robot and the scene.

    Args:
        checker: collision checker holding the robot model, the planning scene and the padding.
        start: full configuration ``(n,)`` over ``checker.model.joint_names``.
        goal: target positions by joint name (joints of ``group``), or a full configuration ``(n,)``.
        group: the planning group that moves.
        options: planner, timeouts, resolution.

    Returns:
        A path over the group's joints; its first row is the start, its last the goal.

    Raises:
        MotionError: invalid joint names, start or goal outside the limits or in collision (naming the
            colliding links), or no path found within the timeout.
    """
    opts = options or PlanningOptions()
    if opts.planner not in PLANNERS:
        raise MotionError(f"unknown planner {opts.planner!r}; {did_you_mean(opts.planner, PLANNERS)}")
    if opts.seed is not None and opts.planner != "RRTConnect":
        raise MotionError(
            f"a seeded plan searches with RRT-Connect; planner {opts.planner!r} cannot be seeded per plan "
            "(OMPL's generator is process-wide): leave the seed out, or use RRTConnect"
        )
    model = checker.model
    g = model.group(group)
    q_start = np.asarray(start, dtype=float)
    if q_start.shape != (len(model.joint_names),):
        raise MotionError(f"start must have {len(model.joint_names)} values ({', '.join(model.joint_names)})")
    outside = (q_start < model.lower - opts.limit_tolerance) | (q_start > model.upper + opts.limit_tolerance)
    if np.any(outside):
        bad = [f"{model.joint_names[i]} = {q_start[i]:.4f}" for i in np.flatnonzero(outside)]
        raise MotionError(f"start state is outside the joint limits: {', '.join(bad)}")
    q_start = np.clip(q_start, model.lower, model.upper)
    if isinstance(goal, Mapping):
        q_goal = goal_configuration(checker, q_start, goal, group)
    else:
        q_goal = q_start.copy()
        full = np.asarray(goal, dtype=float)
        q_goal[list(g.indices)] = full[list(g.indices)]
    cols = list(g.indices)
    stuck = q_start
    if checker.in_collision(q_start):
        colliding = checker.describe(q_start)
        freed = _free_start(checker, q_start, cols, opts) if opts.fix_start_collision else None
        if freed is None:
            raise MotionError(
                f"start state is in collision: {colliding}"
                + (
                    f"; no collision-free state within {opts.start_jiggle_fraction:g} of each joint's range "
                    "around it"
                    if opts.fix_start_collision
                    else ""
                )
            )
        q_start = freed
    if checker.in_collision(q_goal):
        raise MotionError(f"goal state is in collision: {checker.describe(q_goal)}")
    if opts.try_direct and checker.first_invalid(np.array([q_start, q_goal]), opts.max_step) is None:
        path = JointPath(g.joint_names, np.array([q_start[cols], q_goal[cols]]))
    elif opts.seed is not None:
        path = _plan_seeded(checker, q_start, q_goal, cols, g.joint_names, opts)
    else:
        path = _plan_ompl(checker, q_start, q_goal, cols, g.joint_names, opts)
    if q_start is not stuck:
        path = JointPath(path.joint_names, np.vstack((stuck[cols][None, :], path.positions)))
    return path


def _free_start(
    checker: CollisionChecker, q_start: np.ndarray, cols: list[int], opts: PlanningOptions
) -> np.ndarray | None:
    """The collision-free state nearest ``q_start`` among samples around it (moving only ``cols``).

    Samples are drawn in growing boxes (1/16, 1/8, ... up to ``start_jiggle_fraction`` of each joint's
    range), 200 per box, from a fixed seed so the same start gives the same plan; the first box with a free
    sample gives the nearest of its free samples.
    """
    model = checker.model
    span = (model.upper - model.lower)[cols]
    span = np.where(np.isfinite(span), span, 2 * np.pi)
    rng = np.random.default_rng(0)
    fraction = opts.start_jiggle_fraction / 16
    while fraction <= opts.start_jiggle_fraction * (1 + 1e-9):
        found: list[np.ndarray] = []
        for _ in range(200):
            q = q_start.copy()
            q[cols] = np.clip(
                q_start[cols] + rng.uniform(-1.0, 1.0, len(cols)) * fraction * span,
                model.lower[cols],
                model.upper[cols],
            )
            if not checker.in_collision(q):
                found.append(q)
        if found:
            return min(found, key=lambda q: float(np.abs(q[cols] - q_start[cols]).max()))
        fraction *= 2
    return None


def _plan_seeded(
    checker: CollisionChecker,
    q_start: np.ndarray,
    q_goal: np.ndarray,
    cols: list[int],
    names: tuple[str, ...],
    opts: PlanningOptions,
) -> JointPath:
    from kinema.motion.rrt import RrtOptions, rrt_connect

    scratch = q_start.copy()

    def valid(q: np.ndarray) -> bool:
        scratch[cols] = q
        return not checker.in_collision(scratch)

    # Checked at half the step from the start: the path goes to a controller, as OMPL's is re-checked.
    rrt = RrtOptions(
        seed=int(opts.seed or 0),
        max_iterations=opts.max_iterations,
        timeout=opts.timeout,
        max_step=opts.max_step / 2,
    )
    model = checker.model
    positions = rrt_connect(valid, q_start[cols], q_goal[cols], model.lower[cols], model.upper[cols], rrt)
    return JointPath(names, positions)


def _plan_ompl(
    checker: CollisionChecker,
    q_start: np.ndarray,
    q_goal: np.ndarray,
    cols: list[int],
    names: tuple[str, ...],
    opts: PlanningOptions,
) -> JointPath:
    ob, og, _ = _ompl()
    model = checker.model
    k = len(cols)
    lo, hi = model.lower[cols], model.upper[cols]
    space = ob.RealVectorStateSpace(k)
    bounds = ob.RealVectorBounds(k)
    for i in range(k):
        bounds.setLow(i, float(lo[i]))
        bounds.setHigh(i, float(hi[i]))
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    scratch = q_start.copy()

    def valid(state) -> bool:
        scratch[cols] = state[0:k]
        return not checker.in_collision(scratch)

    setup.setStateValidityChecker(valid)
    info = setup.getSpaceInformation()
    # OMPL's resolution is a fraction of the space's extent; convert our per-joint step into it.
    info.setStateValidityCheckingResolution(min(0.05, opts.max_step / float(space.getMaximumExtent())))
    setup.setPlanner(getattr(og, opts.planner)(info))

    def to_state(q: np.ndarray):
        st = space.allocState()
        st[0:k] = [float(x) for x in q[cols]]
        return st

    with _OMPL_LOCK:
        setup.setStartAndGoalStates(to_state(q_start), to_state(q_goal))
        status = setup.solve(float(opts.timeout))
        solved = bool(status) and str(status) == "Exact solution"
        if not solved:
            raise MotionError(
                f"no collision-free path found within {opts.timeout:.2f} s ({opts.planner}: {status}); "
                "the goal may be enclosed by obstacles"
            )
        raw = np.array([s[0:k] for s in setup.getSolutionPath().getStates()])
        setup.simplifySolution(float(opts.simplify_timeout))
        simplified = np.array([s[0:k] for s in setup.getSolutionPath().getStates()])
    for candidate in (simplified, raw):
        path = candidate.copy()
        path[0], path[-1] = q_start[cols], q_goal[cols]
        full = np.repeat(q_start[None, :], len(path), axis=0)
        full[:, cols] = path
        # Re-check at half the planner's step: the path goes to a controller, so be strict.
        if checker.first_invalid(full, opts.max_step / 2) is None:
            return JointPath(names, path)
    raise MotionError("the planned path failed the fine collision check (no valid path within the timeout)")
