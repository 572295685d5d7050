"""Inverse kinematics: damped least squares on pinocchio, within joint limits, from several seeds."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from kinema.errors import MotionError

if TYPE_CHECKING:
    from kinema.motion.robot_model import RobotModel


@dataclass(frozen=True)
class IkOptions:
    """Tuning of :func:`ik`.

    Attributes:
        position_tolerance: accepted position error (m).
        orientation_tolerance: accepted orientation error (rad).
        max_iterations: iterations (damped least-squares steps) per seed.
        attempts: seeds tried in all: the given seed first, then random ones inside the limits.
        restart_solutions: when the given seed fails, random restarts stop after this many solutions and
            the one closest to the seed is returned.
        damping: damped-least-squares damping (m² / rad²).
        max_step: largest joint change per iteration (rad or m); without it the first Gauss-Newton step
            from a far seed jumps to a limit or flips the wrist and the iteration gets stuck.
        rng_seed: seed of the random restarts (deterministic by default).
        timeout: seconds after which no further random restart begins (the seed's attempt always
            runs); None: all ``attempts`` may run.
    """

    position_tolerance: float = 1e-4
    orientation_tolerance: float = 1e-3
    max_iterations: int = 100
    attempts: int = 10
    restart_solutions: int = 3
    damping: float = 1e-6
    max_step: float = 0.2
    rng_seed: int = 0
    timeout: float | None = None


def ik(
    model: RobotModel,
    world_T_target: np.ndarray,
    seed: np.ndarray,
    group: str,
    frame: str | None = None,
    *,
    position_only: bool = False,
    options: IkOptions | None = None,
    accept: Callable[[np.ndarray], bool] | None = None,
) -> np.ndarray:
    """Find a configuration that puts ``frame`` at ``world_T_target``, moving only ``group``'s joints.

    The seed is tried first, so the answer stays on the seed's elbow/wrist branch when one exists there.
    Otherwise random seeds inside the limits follow, and of the solutions they find the one closest to the
    seed (in joint space) is returned. Every solution respects the position limits.

    Args:
        model: the robot model.
        world_T_target: target pose of ``frame`` in the world frame, shape ``(4, 4)``.
        seed: full configuration ``(n,)``; joints outside ``group`` keep these values.
        group: planning group whose joints move.
        frame: the frame to place; defaults to the group's tip link.
        position_only: ignore orientation.
        options: tolerances, iterations and number of seeds.
        accept: an extra test a solution must pass (e.g. "not in collision"); rejected solutions count as
            failed attempts.

    Returns:
        The configuration ``(n,)``.

    Raises:
        MotionError: "no IK solution", with the remaining error and the reason.
    """
    tip = frame or model.group(group).tip_link
    if tip is None:
        raise MotionError(f"group {group!r} has no tip link; pass frame= (one of the robot's links)")
    return ik_tips(
        model,
        [(tip, world_T_target)],
        seed,
        group,
        position_only=position_only,
        options=options,
        accept=accept,
    )


def ik_tips(
    model: RobotModel,
    targets: Sequence[tuple[str, np.ndarray]],
    seed: np.ndarray,
    group: str,
    *,
    position_only: bool = False,
    options: IkOptions | None = None,
    accept: Callable[[np.ndarray], bool] | None = None,
) -> np.ndarray:
    """Find a configuration that puts every frame of ``targets`` at its pose at once (multi-tip IK).

    The same search as :func:`ik` (which is this with one tip), on the tips' stacked errors and
    Jacobians: a solution has every tip within the tolerances. Tips on branches of the group (two arms
    of one group, two fingers) are solved together, sharing the joints they have in common.

    Args:
        model: the robot model.
        targets: ``(frame, world_T_frame)`` pairs, each pose of shape ``(4, 4)`` in the world frame.
        seed, group, position_only, options, accept: as for :func:`ik`.

    Raises:
        MotionError: no targets, a frame named twice, or "no IK solution" with the remaining error
            (the worst tip's) and the reason.
    """
    import pinocchio as pin

    if not targets:
        raise MotionError("IK needs at least one (frame, pose) target")
    tips = [frame for frame, _ in targets]
    if len(set(tips)) != len(tips):
        raise MotionError(f"IK targets name a frame twice: {', '.join(tips)}")
    opts = options or IkOptions()
    g = model.group(group)
    fids = [model.frame_id(tip) for tip in tips]
    goals = [pin.SE3(np.asarray(pose, dtype=float)) for _, pose in targets]
    cols = np.array(g.indices)
    lo, hi = model.lower[cols], model.upper[cols]
    data = model.new_data()
    pm = model.pin_model
    m = 3 if position_only else 6
    rows = m * len(tips)
    rng = np.random.default_rng(opts.rng_seed)
    seed = np.clip(np.asarray(seed, dtype=float), model.lower, model.upper)
    best_error = (np.inf, np.inf)
    rejected = 0
    found: list[np.ndarray] = []
    started = time.monotonic()
    attempts = 0
    single = len(fids) == 1
    damping = opts.damping * np.eye(rows)
    tip_goals = list(zip(fids, goals, strict=True))

    for attempt in range(opts.attempts):
        if len(found) >= opts.restart_solutions:
            break
        if attempt > 0 and opts.timeout is not None and time.monotonic() - started > opts.timeout:
            break
        attempts += 1
        q = seed.copy()
        if attempt > 0:
            q[cols] = rng.uniform(lo, hi)
        # max_iterations steps, each followed by a convergence check (the seed is checked first).
        for iteration in range(opts.max_iterations + 1):
            pq = model.pin_configuration(q)
            pin.framesForwardKinematics(pm, data, pq)
            errors, offsets = [], []
            pos_err = rot_err = 0.0
            for fid, target in tip_goals:
                current_T_target = data.oMf[fid].actInv(target)
                offsets.append(current_T_target)
                if position_only:
                    # Position error in the world frame, so the Jacobian rows below match it.
                    err = target.translation - data.oMf[fid].translation
                    pos_err = max(pos_err, float(np.linalg.norm(err)))
                else:
                    err = pin.log(current_T_target).vector
                    pos_err = max(pos_err, float(np.linalg.norm(err[:3])))
                    rot_err = max(rot_err, float(np.linalg.norm(err[3:])))
                errors.append(err)
            if pos_err < opts.position_tolerance and rot_err < opts.orientation_tolerance:
                if accept is None or accept(q):
                    if attempt == 0:
                        return q
                    found.append(q)
                else:
                    rejected += 1
                break
            if (pos_err, rot_err) < best_error:
                best_error = (pos_err, rot_err)
            if iteration == opts.max_iterations:
                break
            jacobians = []
            for fid, current_T_target in zip(fids, offsets, strict=True):
                if position_only:
                    J = pin.computeFrameJacobian(pm, data, pq, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
                    jacobians.append((J @ model.mimic_map)[:3][:, cols])
                else:
                    J = pin.computeFrameJacobian(pm, data, pq, fid, pin.ReferenceFrame.LOCAL)
                    jacobians.append((pin.Jlog6(current_T_target.inverse()) @ J @ model.mimic_map)[:, cols])
            # One tip (nearly every call): no stacking, which cost a fifth of a one-tip solve.
            J = jacobians[0] if single else np.vstack(jacobians)
            e = errors[0] if single else np.concatenate(errors)
            dq = J.T @ np.linalg.solve(J @ J.T + damping, e)
            largest = float(np.abs(dq).max())
            if largest > opts.max_step:
                dq *= opts.max_step / largest
            q[cols] = np.clip(q[cols] + dq, lo, hi)
    if found:
        return min(found, key=lambda sol: float(np.linalg.norm(sol - seed)))
    reason = (
        f"{rejected} solution(s) found but rejected (e.g. in collision)"
        if rejected
        else "the target may be out of reach or outside the joint limits"
    )
    where = "; ".join(
        f"{tip!r} in group {group!r} at position {np.round(target.translation, 4).tolist()}"
        for tip, target in zip(tips, goals, strict=True)
    )
    raise MotionError(
        f"no IK solution for {where} after {attempts} seed(s) of "
        f"{opts.max_iterations} iteration(s) each: best error "
        f"{best_error[0]:.4f} m / {best_error[1]:.4f} rad; {reason}"
    )
