"""The generated ``Home`` of a robot whose SRDF names none: its rest pose, or a bent pose to work from.

The rest pose is every joint at 0 (mid-range where 0 is outside the limits). Many URDFs define 0 as the arm
stretched out, which is no place to start from: example-robot-data's UR10 lies flat along the table at 0,
its elbow and wrist singular, and every Cartesian move from there fails. The rule, deterministic:

1. The rest pose is **workable**, and kept, when all of these hold:

   - the planning group's manipulability at the tool frame is at least :data:`MIN_MANIPULABILITY`;
   - nothing collides (the robot with itself, the SRDF's disabled pairs left out, and with the table);
   - the arm does not lie on the table: the tool frame and the origin of every joint that a tilting joint
     carries (an elbow, a wrist) are at least :data:`MIN_HEIGHT` arm lengths above the table top;
   - the tool can move :func:`move_step` along +x, -x, +y, -y, +z and -z of the world, its orientation kept
     (position only for a group of fewer than six joints): IK from the pose itself, collision-free.

2. Otherwise the candidates are the rest pose with each of the group's joints but its first and last
   (the base's turn and the tool's roll, which change neither reach nor dexterity) moved by 0, ±45° or ±90°
   (within limits). Of those whose manipulability is at least half the best candidate's, the one bent least
   (the smallest sum of the joints' changes) that is workable is Home; ties go to the higher manipulability,
   then to the order of the candidates. Where no candidate is workable the rest pose stays (a note says so).

Manipulability is Yoshikawa's ``sqrt(det(J Jᵀ))`` (the product of J's singular values) of the tool frame's
6-by-n Jacobian over the group's joints, its translational rows divided by the arm's length ``L`` (the sum of
the distances between successive joints, to the tool frame): dimensionless, so an arm's size does not
change it. Measured on example-robot-data's arms without their SRDFs: the SO-101's and SO-100's rest
poses, which are workable, have 0.082 and 0.024; the UR3's, UR5's, UR10's, xArm7's and Kinova's (stretched
out or upright) have 0, an exact singularity; the Z1's (folded, its wrist axes nearly in line) 0.0025; the
Homes chosen for those have 0.020-0.10.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from kinema.errors import MotionError

if TYPE_CHECKING:
    from kinema.motion.collision import CollisionChecker
    from kinema.motion.robot_model import RobotModel

#: Below this manipulability a pose is near-singular: a pose whose elbow or wrist is straight has 0, and the
#: workable poses measured have at least twice it (see the module docstring).
MIN_MANIPULABILITY = 0.01
#: The tool frame and the arm's elbow and wrist joints stay this share of the arm's length above the table
#: (a UR10, 1.75 m from shoulder to tool: 26 cm; lying along the table at rest, its wrist is 1 cm above it).
MIN_HEIGHT = 0.15
#: Candidates within this share of the best manipulability count as equally good: the least bent is chosen.
GOOD_SHARE = 0.5
#: The bends tried on each joint, rad: none, then 45° and 90° either way.
BENDS = (0.0, math.pi / 4, -math.pi / 4, math.pi / 2, -math.pi / 2)
#: At most this many joints are bent (the ones nearest the base): 5**6 candidates.
MAX_BENT_JOINTS = 6
#: At most this many collision-free candidates get the IK test (each takes six IK solves).
MAX_IK_TESTS = 25
#: The table, for the test: a slab under the table top at the robot's base, wider than any generated table.
TABLE = "table"


@dataclass
class HomeChoice:
    """What :func:`choose_home` decided.

    Attributes:
        positions: the group's joint values at Home (rad or m).
        changed: whether Home differs from the rest pose.
        problems: why the rest pose is not workable (empty when it is).
        rest_manipulability: the rest pose's manipulability.
        manipulability: Home's.
        tool_height: the tool frame's height above the table top at Home, m.
    """

    positions: dict[str, float]
    changed: bool
    problems: list[str] = field(default_factory=list)
    rest_manipulability: float = 0.0
    manipulability: float = 0.0
    tool_height: float = 0.0


def move_step(arm_length: float) -> float:
    """How far (m) the tool must be able to move from Home along each axis: 5 cm, or a tenth of a small
    arm's length (an SO-101's 4.5 cm)."""
    return min(0.05, 0.1 * arm_length)


class _Judge:
    """Measures poses of one group: manipulability, heights above the table, collisions, room to move."""

    def __init__(
        self, model: RobotModel, group: str, tool_frame: str, rest: np.ndarray, table_top: float
    ) -> None:
        import pinocchio as pin

        from kinema.motion.collision import CollisionChecker
        from kinema.motion.planning_scene import PlanningScene

        self.model, self.group, self.tool_frame = model, group, tool_frame
        self.table_top, self.rest = table_top, rest
        self.columns = list(model.group(group).indices)
        self.tool = model.frame_id(tool_frame)
        self.data = model.new_data()
        pm = model.pin_model
        joint_ids = [pm.getJointId(model.joint_names[i]) for i in self.columns]
        pin.framesForwardKinematics(pm, self.data, model.pin_configuration(rest))
        points = [self.data.oMi[j].translation.copy() for j in joint_ids]
        points.append(self.data.oMf[self.tool].translation.copy())
        #: The arm's length, m: the distances between successive joints of the group, to the tool frame.
        self.length = max(float(sum(np.linalg.norm(b - a) for a, b in itertools.pairwise(points))), 1e-3)
        self.carried = self._carried_joints()
        scene = PlanningScene()
        reach = self.length + 1.0
        table_T = np.eye(4)
        table_T[:3, 3] = (0.0, 0.0, table_top - 0.05)
        scene.add_box(TABLE, (reach, reach, 0.05), table_T)
        self.checker: CollisionChecker = CollisionChecker(model, scene)
        # Links no joint can raise or lower (a shoulder turning about a vertical axis) stand on the table as
        # they were built: neither the rest pose nor any candidate can move them off it.
        self.checker.allowed_collisions = [(link, TABLE) for link in self._level_links()]

    def _lifting(self) -> set[int]:
        """The pinocchio joints that move what they carry up or down (at the rest pose): a revolute joint
        whose axis is not vertical, a prismatic one whose axis is not horizontal."""
        import pinocchio as pin

        pm = self.model.pin_model
        pin.computeJointJacobians(pm, self.data, self.model.pin_configuration(self.rest))
        lifting = set()
        for jid in range(1, pm.njoints):
            # A one-joint model's Jacobian comes back as a vector: shaped (6, nv) again.
            jacobian = np.reshape(pin.getJointJacobian(pm, self.data, jid, pin.WORLD), (6, pm.nv))
            column = jacobian[:, pm.idx_vs[jid]]
            linear, angular = column[:3], column[3:]
            if np.linalg.norm(angular) > 1e-9:
                if abs(angular[2]) < 0.999 * np.linalg.norm(angular):
                    lifting.add(jid)
            elif abs(linear[2]) > 1e-3 * max(float(np.linalg.norm(linear)), 1e-9):
                lifting.add(jid)
        return lifting

    def _lifted(self, jid: int, lifting: set[int]) -> bool:
        parents = self.model.pin_model.parents
        while jid:
            if jid in lifting:
                return True
            jid = parents[jid]
        return False

    def _carried_joints(self) -> list[int]:
        lifting = self._lifting()
        pm = self.model.pin_model
        return [j for j in range(1, pm.njoints) if self._lifted(int(pm.parents[j]), lifting)]

    def _level_links(self) -> list[str]:
        import pinocchio as pin

        lifting = self._lifting()
        frames = self.model.pin_model.frames
        return [
            f.name
            for f in frames
            if f.type == pin.FrameType.BODY and not self._lifted(f.parentJoint, lifting)
        ]

    def manipulability(self, q: np.ndarray) -> float:
        import pinocchio as pin

        pm = self.model.pin_model
        pin.computeJointJacobians(pm, self.data, self.model.pin_configuration(q))
        pin.updateFramePlacements(pm, self.data)
        frame = np.reshape(
            pin.getFrameJacobian(pm, self.data, self.tool, pin.LOCAL_WORLD_ALIGNED), (6, pm.nv)
        )
        jacobian = (frame @ self.model.mimic_map)[:, self.columns]
        jacobian[:3] /= self.length
        return float(np.prod(np.linalg.svd(jacobian, compute_uv=False)))

    def heights(self, q: np.ndarray) -> tuple[float, tuple[str, float] | None]:
        """The tool frame's height above the table top, and the lowest joint a tilting joint carries
        (name, height), m; the data's placements are left at ``q``."""
        import pinocchio as pin

        pm = self.model.pin_model
        pin.framesForwardKinematics(pm, self.data, self.model.pin_configuration(q))
        tool = float(self.data.oMf[self.tool].translation[2]) - self.table_top
        lowest = min(
            ((pm.names[j], float(self.data.oMi[j].translation[2]) - self.table_top) for j in self.carried),
            key=lambda item: item[1],
            default=None,
        )
        return tool, lowest

    def low(self, q: np.ndarray) -> str | None:
        """Why ``q`` lies on the table, or None."""
        least = MIN_HEIGHT * self.length
        tool, lowest = self.heights(q)
        if tool < least:
            where = f"{_height(tool)} the table top"
            return f"its tool frame {self.tool_frame} is {where} (under {least:.2f} m above)"
        if lowest is not None and lowest[1] < least:
            return f"it lies on the table ({lowest[0]} {_height(lowest[1])} it, under {least:.2f} m above)"
        return None

    def stuck(self, q: np.ndarray) -> str | None:
        """The first direction the tool cannot move :func:`move_step` in from ``q``, or None."""
        from kinema.motion.inverse_kinematics import IkOptions, ik

        step = move_step(self.length)
        options = IkOptions(attempts=1)  # from the pose itself: a move that needs another branch is no move
        position_only = len(self.columns) < 6
        start = self.tool_pose(q)
        for axis, sign in itertools.product(range(3), (1.0, -1.0)):
            goal = start.copy()
            goal[axis, 3] += sign * step
            try:
                ik(
                    self.model,
                    goal,
                    q,
                    self.group,
                    self.tool_frame,
                    position_only=position_only,
                    options=options,
                    accept=lambda solution: not self.checker.in_collision(solution),
                )
            except MotionError:
                return f"{'+' if sign > 0 else '-'}{'xyz'[axis]}"
        return None

    def tool_pose(self, q: np.ndarray) -> np.ndarray:
        from kinema.motion.kinematics import fk

        return fk(self.model, q, self.tool_frame, self.data)

    def problems(self, q: np.ndarray, manipulability: float) -> list[str]:
        """Everything that keeps ``q`` from being workable (empty: workable)."""
        found = []
        if manipulability < MIN_MANIPULABILITY:
            found.append(f"near-singular (manipulability {manipulability:.3f} < {MIN_MANIPULABILITY})")
        if (low := self.low(q)) is not None:
            found.append(low)
        if self.checker.in_collision(q):
            found.append(f"in collision ({self.checker.describe(q)})")
        elif not found and (direction := self.stuck(q)) is not None:
            step = move_step(self.length) * 100
            found.append(f"its tool cannot move {step:.0f} cm along {direction} (no IK solution)")
        return found


def choose_home(
    model: RobotModel,
    group: str,
    tool_frame: str,
    rest: Mapping[str, float],
    *,
    table_top: float = 0.0,
) -> HomeChoice:
    """Home for ``group``: ``rest`` when it is workable, else the least bent workable candidate (see the
    module docstring).

    Args:
        model: the robot, its SRDF's disabled pairs included (a generated SRDF's too).
        group: the planning group.
        tool_frame: the link or frame Cartesian moves place.
        rest: joint values of the rest pose by name (joints outside the group keep theirs).
        table_top: the height of the table top in the robot's root frame, m.

    Raises:
        MotionError: an unknown group or frame, or collision geometry pinocchio cannot read.
    """
    names = model.joint_names
    start = model.configuration({n: v for n, v in rest.items() if n in names})
    judge = _Judge(model, group, tool_frame, start, table_top)
    group_names = [names[i] for i in judge.columns]
    rest_w = judge.manipulability(start)
    if len(group_names) < 2:
        # One joint has no posture to choose (and kinema.motion's IK wants groups of two joints or more).
        return HomeChoice({n: float(start[model.index(n)]) for n in group_names}, False, [], rest_w, rest_w)
    problems = judge.problems(start, rest_w)

    def choice(q: np.ndarray, w: float, changed: bool) -> HomeChoice:
        tool, _ = judge.heights(q)
        positions = {n: round(float(q[model.index(n)]), 6) for n in group_names}
        return HomeChoice(positions, changed, problems, rest_w, w, tool)

    if not problems:
        return choice(start, rest_w, False)
    bent = judge.columns[1:-1] if len(judge.columns) > 2 else judge.columns
    bent = bent[:MAX_BENT_JOINTS]
    candidates: list[tuple[float, float, int, np.ndarray]] = []
    for order, bends in enumerate(itertools.product(BENDS, repeat=len(bent))):
        if not any(bends):
            continue
        q = start.copy()
        q[bent] += bends
        if not model.within_limits(q):
            continue
        w = judge.manipulability(q)
        if w < MIN_MANIPULABILITY or judge.low(q) is not None:
            continue
        candidates.append((w, float(np.abs(bends).sum()), order, q))
    if not candidates:
        return choice(start, rest_w, False)
    good = GOOD_SHARE * max(w for w, *_ in candidates)
    candidates.sort(key=lambda c: (c[0] < good, c[1], -c[0], c[2]))
    tested = 0
    for w, _bend, _order, q in candidates:
        if judge.checker.in_collision(q):
            continue
        if judge.stuck(q) is None:
            return choice(q, w, True)
        tested += 1
        if tested >= MAX_IK_TESTS:
            break
    return choice(start, rest_w, False)


def home_note(choice: HomeChoice, rest_words: str, how_to_change: str) -> str | None:
    """What a user reads about Home when :func:`choose_home` found the rest pose wanting (None otherwise)."""
    if not choice.problems:
        return None
    why = "; ".join(choice.problems)
    if not choice.changed:
        return f"Home is {rest_words}, though it is {why}: no bent pose was better. {how_to_change}"
    values = ", ".join(f"{n}={v:g}" for n, v in choice.positions.items())
    return (
        f"Home is not {rest_words}, which is {why}: it is the least bent pose (joints moved by 45° or 90°) "
        f"from which the tool can move along every axis, manipulability {choice.manipulability:.3f} "
        f"(at rest {choice.rest_manipulability:.3f}), tool frame {choice.tool_height:.2f} m above the table: "
        f"{values}. {how_to_change}"
    )


def _height(metres: float) -> str:
    """``0.12 m above`` or ``0.01 m below``: a height under the table top is said so, not "-0.01 m above"."""
    return f"{metres:.2f} m above" if metres >= 0 else f"{-metres:.2f} m below"
