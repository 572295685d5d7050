"""Cartesian paths: move a tool frame along straight lines (with slerped orientation) by IK interpolation."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from kinema.errors import MotionError
from kinema.motion.blending import blended_pieces
from kinema.motion.collision import CollisionChecker
from kinema.motion.inverse_kinematics import IkOptions, ik
from kinema.motion.kinematics import fk
from kinema.motion.trajectory import JointPath


@dataclass(frozen=True, eq=False)  # holds numpy arrays: compare fields explicitly
class CartesianResult:
    """A Cartesian path and how much of the requested motion it covers.

    Attributes:
        path: the joint path over the group's joints (its first row is the start).
        fraction: share of the requested Cartesian length achieved, 0..1 (1 = all of it).
        reason: why it stopped early ("" when ``fraction`` is 1).
    """

    path: JointPath
    fraction: float
    reason: str = ""


def plan_cartesian_path(
    checker: CollisionChecker,
    start: np.ndarray,
    world_T_waypoints: Sequence[np.ndarray],
    group: str,
    frame: str | None = None,
    *,
    max_step: float = 0.005,
    max_rotation_step: float = 0.05,
    jump_threshold: float = 0.3,
    position_only: bool = False,
    blending_radius: float = 0.0,
    max_iterations: int = 50,
) -> CartesianResult:
    """Move ``frame`` through ``world_T_waypoints`` in straight lines, solving IK every ``max_step`` metres.

    With ``blending_radius`` > 0 each interior corner is rounded by a circular arc that leaves the lines
    that far from the waypoint (see :func:`kinema.motion.blending.blended_pieces`); the last waypoint is
    still reached exactly.

    Each step's IK is seeded with the previous step's answer, so the arm stays on one branch. The path
    stops early (``fraction`` < 1) at the first step with no IK solution, a joint jump larger than
    ``jump_threshold`` (rad or m), or a collision.

    Args:
        checker: collision checker (robot model, scene, padding).
        start: full configuration ``(n,)`` the motion starts from.
        world_T_waypoints: poses of ``frame`` to pass through, each ``(4, 4)``, world frame.
        group: planning group that moves.
        frame: tool frame; the group's tip link by default.
        max_step: largest translation between IK solutions (m).
        max_rotation_step: largest rotation between IK solutions (rad).
        jump_threshold: largest joint change allowed between consecutive solutions.
        position_only: only the position of ``frame`` follows the line.
        blending_radius: distance (m) from each interior waypoint at which its corner blend starts and
            ends; 0 passes through every waypoint.
        max_iterations: iteration cap of each step's IK (seeded by the previous step); a step whose IK
            does not converge within it stops the path.

    Raises:
        MotionError: no waypoints, an unknown group/frame, a start in collision, a negative blending
            radius or an iteration cap below 1.
    """

    model = checker.model
    g = model.group(group)
    tip = frame or g.tip_link
    if tip is None:
        raise MotionError(f"group {group!r} has no tip link; pass frame=")
    if not world_T_waypoints:
        raise MotionError("a Cartesian path needs at least one waypoint")
    q = np.clip(np.asarray(start, dtype=float), model.lower, model.upper)
    if checker.in_collision(q):
        raise MotionError(f"start state is in collision: {checker.describe(q)}")
    cols = list(g.indices)
    data = model.new_data()
    current = fk(model, q, tip, data)
    if blending_radius < 0:
        raise MotionError(f"blending_radius must be >= 0 (m), got {blending_radius}")
    if max_iterations < 1:
        raise MotionError(f"the IK iteration cap must be >= 1, got {max_iterations}")
    poses = [current, *(np.asarray(T, dtype=float) for T in world_T_waypoints)]
    pieces = blended_pieces(poses, blending_radius)
    total = sum(piece.length for piece in pieces)
    rotation_total = sum(piece.rotation for piece in pieces)
    rows = [q[cols].copy()]
    done = 0.0
    done_rotation = 0.0
    options = IkOptions(attempts=1, max_iterations=max_iterations)
    reason = ""
    for piece in pieces:
        seg, angle = piece.length, piece.rotation
        steps = max(1, int(np.ceil(max(seg / max_step, 0 if position_only else angle / max_rotation_step))))
        for s in range(1, steps + 1):
            target = piece.pose_at(s / steps)
            try:
                q_next = ik(model, target, q, group, tip, position_only=position_only, options=options)
            except MotionError as error:
                reason = (
                    f"no IK solution at {np.round(target[:3, 3], 4).tolist()}: the IK did not converge "
                    f"within {max_iterations} iteration(s) ({error})"
                )
                break
            jump = float(np.abs(q_next[cols] - q[cols]).max())
            if jump > jump_threshold:
                reason = (
                    f"joint jump of {jump:.3f} exceeds the threshold {jump_threshold} at "
                    f"{np.round(target[:3, 3], 4).tolist()}: usually the path nears the edge of the arm's "
                    "reach or a singularity there (a shorter move or a joint-space move avoids it; a larger "
                    "threshold allows the jump)"
                )
                break
            if checker.first_invalid(np.array([q, q_next]), 0.01) is not None:
                reason = f"collision: {checker.describe(q_next)}"
                break
            q = q_next
            rows.append(q[cols].copy())
        else:
            done += seg
            done_rotation += angle
            continue
        done += seg * (s - 1) / steps
        done_rotation += angle * (s - 1) / steps
        break
    if total > 1e-9:
        fraction = done / total
    elif rotation_total > 1e-9:
        fraction = done_rotation / rotation_total
    else:
        fraction = 1.0
    return CartesianResult(JointPath(g.joint_names, np.array(rows)), min(1.0, fraction), reason)
