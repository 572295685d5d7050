"""Orientation constraints checked along a motion: a link stays within an angle of where it started.

Kinema's planners take no path constraints, so a constraint is a check on a planned motion (and on the
IK goal): :class:`OrientationKeeper` remembers each constrained link's orientation at the start and
reports the first configuration that turns one further than its ``angle_tolerance``. Between two rows of
a motion it checks joint-space interpolations no more than :data:`CHECK_STEP` apart, as the motion is
timed and executed by joint interpolation.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from kinema.errors import MotionError
from kinema.transforms import rotation_angle

if TYPE_CHECKING:
    from kinema.motion.robot_model import RobotModel
    from kinema.motion.task_stages import OrientationConstraint

CHECK_STEP = 0.02  # rad or m: largest joint change between two checked configurations


class OrientationKeeper:
    """The constraints of one motion starting at ``q_start`` (a full configuration).

    Raises:
        MotionError: a constraint names a frame the robot model does not have.
    """

    def __init__(
        self, model: RobotModel, q_start: np.ndarray, constraints: Sequence[OrientationConstraint]
    ) -> None:
        from kinema.errors import did_you_mean
        from kinema.motion.kinematics import fk

        self.model = model
        self.constraints = tuple(constraints)
        frames = [frame.name for frame in model.pin_model.frames]
        for constraint in self.constraints:
            if constraint.link not in frames:
                raise MotionError(
                    f"orientation constraint names {constraint.link!r}, no frame of the robot; "
                    f"{did_you_mean(constraint.link, model.link_names)}"
                )
        self._data = model.new_data()
        self.start = [fk(model, q_start, c.link, self._data)[:3, :3] for c in self.constraints]
        self._q_start = np.asarray(q_start, dtype=float)

    def target_problem(self, world_T_target: np.ndarray, ik_frame: str) -> str:
        """Why putting ``ik_frame`` at ``world_T_target`` cannot keep a constraint on a link rigidly
        attached to it, or "" (links that move relative to ``ik_frame`` are checked on the IK solution)."""
        from kinema.motion.kinematics import fk

        world_T_ik = fk(self.model, self._q_start, ik_frame, self._data)
        for constraint, start in zip(self.constraints, self.start, strict=True):
            if not self._rigid(ik_frame, constraint.link):
                continue
            ik_T_link = np.linalg.inv(world_T_ik) @ fk(self.model, self._q_start, constraint.link, self._data)
            angle = rotation_angle(start, (world_T_target @ ik_T_link)[:3, :3])
            if angle > constraint.angle_tolerance + 1e-9:
                return (
                    f"the target pose turns {constraint.link} {angle:.3f} rad from its orientation at the "
                    f"start, more than the orientation constraint's {constraint.angle_tolerance:.3f} rad"
                )
        return ""

    def _rigid(self, a: str, b: str) -> bool:
        """True when frames ``a`` and ``b`` hang from the same joint (none moves one without the other)."""
        pin = self.model.pin_model
        return bool(pin.frames[pin.getFrameId(a)].parentJoint == pin.frames[pin.getFrameId(b)].parentJoint)

    def violation(self, rows: np.ndarray) -> str:
        """How the motion through the full configurations ``rows`` (interpolated between them) first breaks
        a constraint (``<link> turns 0.412 rad (> 0.200) at 37 %``), or "" when it keeps them all."""
        from kinema.motion.kinematics import fk

        if not self.constraints:
            return ""
        rows = np.atleast_2d(np.asarray(rows, dtype=float))
        dense = [rows[0]]
        for a, b in itertools.pairwise(rows):
            steps = max(1, int(np.ceil(np.abs(b - a).max() / CHECK_STEP)))
            dense += [a + (b - a) * k / steps for k in range(1, steps + 1)]
        for k, q in enumerate(dense):
            for constraint, start in zip(self.constraints, self.start, strict=True):
                angle = rotation_angle(start, fk(self.model, q, constraint.link, self._data)[:3, :3])
                if angle > constraint.angle_tolerance + 1e-9:
                    where = 100.0 * k / max(1, len(dense) - 1)
                    return (
                        f"{constraint.link} turns {angle:.3f} rad (> {constraint.angle_tolerance:.3f}) "
                        f"at {where:.0f} % of the motion"
                    )
        return ""
