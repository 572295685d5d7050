"""Model predictive control of a frame's pose: one small QP per control step (ProxQP on pinocchio).

Each step plans the next ``horizon`` seconds as ``N = horizon / timestep`` joint positions
``q_1 .. q_N`` (the group's joints; the others hold) from the measured ``q_0``, and the caller sends that
plan to a trajectory controller; the next step replans from the next measurement (receding horizon).

The QP, linearised around the previous plan shifted to now (a real-time iteration of sequential QP):

- **cost**: the tracked frame's pose error to the target at each step, ``||W (err_k - J_k (q_k - q̄_k))||²``
  with ``err_k = log6(world_T_frame(q̄_k)^-1 world_T_target(t_k))`` (the target moves on with its twist
  over the horizon), weighted ``position_weight`` per metre and ``orientation_weight`` per radian; plus
  small penalties on joint velocity and acceleration that keep the plan smooth and the QP well posed;
- **joint constraints**: position limits, velocity limits (``velocity_scale`` of the model's) and
  acceleration limits, the first step's acceleration measured from the velocity the previous plan had now;
- **Cartesian speed**: optionally, the linear speed of one frame at most ``max_cartesian_speed`` along
  each of 7 directions (the axes and the cube's diagonals), scaled so the speed never exceeds it;
- **clearance**: optionally, each clearance frame (a point on the robot) keeps ``safe_distance`` from the
  surface of its nearest obstacle spheres (points of a cloud are spheres of radius 0), linearised at each
  step. Where the robot is already closer, it may come no closer (so the QP stays feasible), and a linear
  cost pushes it back out.

Every solve starts cold: warm-starting ProxQP from the previous, shifted plan took several times the
iterations once clearance constraints were active.

Units: metres, radians, seconds; ``world`` is the robot model's root frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from kinema import transforms
from kinema.errors import MotionError

if TYPE_CHECKING:
    from kinema.motion.robot_model import RobotModel

# Unit directions the Cartesian speed is limited along: the axes and the four diagonals of the cube. The
# polytope |n·v| <= 1 they bound reaches at most SPEED_POLYTOPE_REACH from the origin (at (1, 1, √3-2)),
# so bounding each by max/SPEED_POLYTOPE_REACH keeps the speed under max in every direction.
_DIRECTIONS = np.vstack(
    (np.eye(3), np.array([[1, 1, 1], [1, 1, -1], [1, -1, 1], [-1, 1, 1]], dtype=float) / np.sqrt(3.0))
)
SPEED_POLYTOPE_REACH = float(np.sqrt(2.0 + (np.sqrt(3.0) - 2.0) ** 2))
# Inside the clearance, the cost of each metre closer to an obstacle (per step and obstacle), against
# tracking costs of order 1 per metre: the robot backs out unless the target pulls much harder.
CLEARANCE_PUSH = 1.0
# How many obstacle spheres each clearance frame keeps its distance from, per step (the nearest ones).
NEAREST_OBSTACLES = 6


@dataclass(frozen=True)
class MpcSettings:
    """What one MPC step optimises.

    Attributes:
        horizon: seconds planned ahead.
        timestep: seconds between planned points (and between control steps).
        position_weight: cost of a metre of position error of the tracked frame.
        orientation_weight: cost of a radian of orientation error.
        velocity_weight: cost of joint speed (per rad/s or m/s, squared).
        acceleration_weight: cost of joint acceleration (per rad/s², squared).
        velocity_scale: fraction of the model's joint velocity limits the plan may use.
        max_joint_speed: a cap on every joint's speed below its limit (rad/s or m/s; None: none).
        acceleration_scale: fraction of the model's joint acceleration limits.
        cartesian_frame: the frame whose linear speed is limited (None: no limit).
        max_cartesian_speed: that limit, m/s.
        clearance_frames: frames of the robot that keep ``safe_distance`` from the obstacles.
        safe_distance: clearance kept between those frames and the obstacles' surfaces, m.
    """

    horizon: float = 0.2
    timestep: float = 0.01
    position_weight: float = 1.0
    orientation_weight: float = 0.25
    velocity_weight: float = 1e-4
    acceleration_weight: float = 1e-7
    velocity_scale: float = 1.0
    max_joint_speed: float | None = None
    acceleration_scale: float = 1.0
    cartesian_frame: str | None = None
    max_cartesian_speed: float | None = None
    clearance_frames: tuple[str, ...] = ()
    safe_distance: float = 0.0

    @property
    def steps(self) -> int:
        """Planned points: ``round(horizon / timestep)``, at least 1."""
        return max(1, round(self.horizon / self.timestep))

    def check(self) -> None:
        """Raise MotionError naming the first value out of range."""
        if not self.timestep > 0:
            raise MotionError(f"the MPC timestep must be > 0 s, got {self.timestep:g}")
        if not self.horizon >= self.timestep:
            raise MotionError(
                f"the MPC horizon ({self.horizon:g} s) must be at least one timestep ({self.timestep:g} s)"
            )
        if self.steps > 200:
            raise MotionError(
                f"the MPC horizon of {self.horizon:g} s at {self.timestep:g} s steps is {self.steps} "
                "steps; at most 200 are solved in real time"
            )
        if not 0 < self.velocity_scale <= 1 or not 0 < self.acceleration_scale <= 1:
            raise MotionError("the MPC velocity and acceleration scales must be in (0, 1]")
        if self.max_cartesian_speed is not None and not self.max_cartesian_speed > 0:
            raise MotionError(
                f"the maximum Cartesian speed must be > 0 m/s, got {self.max_cartesian_speed:g}"
            )
        if self.max_joint_speed is not None and not self.max_joint_speed > 0:
            raise MotionError(f"the joint speed cap must be > 0, got {self.max_joint_speed:g}")
        if self.safe_distance < 0:
            raise MotionError(f"the safe distance must be >= 0 m, got {self.safe_distance:g}")


@dataclass(frozen=True)
class Obstacles:
    """Spheres to keep clear of, in the world frame: centres ``(M, 3)`` and radii ``(M,)`` (m).

    A point cloud is spheres of radius 0 (:meth:`from_points`).
    """

    centres: np.ndarray
    radii: np.ndarray
    _tree: Any = field(default=None, compare=False, repr=False)

    @classmethod
    def from_spheres(cls, centres: Any, radii: Any) -> Obstacles:
        """Spheres; ``radii`` is one radius per centre, or one for all."""
        centres = np.asarray(centres, dtype=float).reshape(-1, 3)
        radii = np.broadcast_to(np.asarray(radii, dtype=float), (len(centres),)).copy()
        if len(centres) and (not np.isfinite(centres).all() or (radii < 0).any()):
            raise MotionError("obstacle spheres need finite centres and radii >= 0")
        from scipy.spatial import cKDTree

        tree = cKDTree(centres) if len(centres) else None
        return cls(centres, radii, tree)

    @classmethod
    def from_points(cls, points: Any) -> Obstacles:
        """The points of a cloud ``(M, 3)``, as spheres of radius 0 (non-finite points dropped)."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        return cls.from_spheres(points[np.isfinite(points).all(axis=1)], 0.0)

    def __len__(self) -> int:
        return len(self.centres)

    def nearest(self, point: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
        """The ``count`` obstacles whose surfaces are nearest ``point``: (indices, surface distances)."""
        if self._tree is None:
            return np.zeros(0, dtype=int), np.zeros(0)
        # Candidates by centre distance, re-ranked by surface distance (radii may differ).
        k = min(len(self.centres), 2 * count if self.radii.any() else count)
        _, index = self._tree.query(point, k=k)
        index = np.atleast_1d(index)
        distance = np.linalg.norm(self.centres[index] - point, axis=1) - self.radii[index]
        order = np.argsort(distance)[:count]
        return index[order], distance[order]

    def distance(self, point: np.ndarray) -> float:
        """Distance from ``point`` to the nearest obstacle surface (negative inside one; inf without any)."""
        _, distance = self.nearest(np.asarray(point, dtype=float), 1)
        return float(distance[0]) if len(distance) else float("inf")


@dataclass(frozen=True)
class MpcPlan:
    """One step's answer.

    Attributes:
        joint_names: the group's joints, the columns of ``positions`` and ``velocities``.
        start: the time of ``q_0`` (the measurement the plan starts from), s.
        times: the planned points' times after ``start``, shape ``(N,)``.
        positions: planned joint positions, shape ``(N, m)``.
        velocities: the velocities between the points (backward differences), shape ``(N, m)``.
        cost: the plan's weighted tracking cost, summed over its steps (as linearised).
        position_error: the tracked frame's distance to the target at ``start``, m.
        orientation_error: its angle to the target's orientation at ``start``, rad.
        clearance: the smallest distance of a clearance frame to an obstacle's surface at ``start`` (the
            measured configuration; inf without obstacles or clearance frames).
    """

    joint_names: tuple[str, ...]
    start: float
    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    cost: float
    position_error: float
    orientation_error: float
    clearance: float


def target_path(world_T_target: np.ndarray, twist: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Where a target moving at ``twist`` will be at ``times``: shape ``(len(times), 4, 4)``.

    Args:
        world_T_target: the target's pose now, ``(4, 4)``.
        twist: its linear (m/s) and angular (rad/s) velocity in the world frame, ``(6,)``.
        times: seconds from now.
    """
    from kinema.transforms import rotation_from_rotvec

    twist = np.asarray(twist, dtype=float)
    poses = np.repeat(np.asarray(world_T_target, dtype=float)[None], len(times), axis=0)
    poses[:, :3, 3] += np.outer(times, twist[:3])
    if twist[3:].any():
        turns = rotation_from_rotvec(np.outer(times, twist[3:]))
        poses[:, :3, :3] = turns @ poses[:, :3, :3]
    return poses


class PoseTrackingMpc:
    """Plans, step after step, joint motions that bring ``frame`` onto a moving target (module docstring).

    Not thread-safe (it keeps pinocchio scratch data and the previous plan).

    Args:
        model: the robot model (pinocchio).
        group: the planning group whose joints move.
        frame: the frame that tracks the target (a link or frame of the model).
        settings: horizon, weights and constraints.

    Raises:
        MotionError: an unknown group or frame (with the valid names), or settings out of range.
    """

    def __init__(self, model: RobotModel, group: str, frame: str, settings: MpcSettings) -> None:
        settings.check()
        self.model = model
        self.settings = settings
        self.group = model.group(group)
        self.frame = frame
        self._frame_id = model.frame_id(frame)
        self._cartesian_id = (
            model.frame_id(settings.cartesian_frame)
            if settings.cartesian_frame and settings.max_cartesian_speed is not None
            else None
        )
        self._clearance_ids = [model.frame_id(name) for name in settings.clearance_frames]
        self._columns = np.array(self.group.indices, dtype=int)
        self._data = model.new_data()
        m, n = len(self._columns), settings.steps
        self._m, self._n = m, n
        dt = settings.timestep
        self._times = dt * np.arange(1, n + 1)
        # First and second differences of the stacked plan x = (q_1, ..., q_N): D1 x - c1 = dt * velocity.
        eye = np.eye(n)
        self._d1 = np.kron(eye - np.eye(n, k=-1), np.eye(m))
        self._d2 = np.kron(eye - 2 * np.eye(n, k=-1) + np.eye(n, k=-2), np.eye(m))
        self._velocity_limit = model.max_velocity[self._columns] * settings.velocity_scale
        if settings.max_joint_speed is not None:
            self._velocity_limit = np.minimum(self._velocity_limit, settings.max_joint_speed)
        self._acceleration_limit = model.max_acceleration[self._columns] * settings.acceleration_scale
        # The previous plan: (start, q_0, positions (N, m), velocities (N, m)), group columns.
        self._previous: tuple[float, np.ndarray, np.ndarray, np.ndarray] | None = None
        self._qp: Any = None
        self._qp_shape = (0, 0)
        #: Steps whose QP had no solution with every bound and was solved again relaxed.
        self.relaxed_steps = 0

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The group's joints, the columns of each plan."""
        return self.group.joint_names

    def reset(self) -> None:
        """Forget the previous plan (the next step starts from rest)."""
        self._previous = None

    # -- one step --------------------------------------------------------------------------------

    def step(
        self,
        q0: np.ndarray,
        start: float,
        world_T_target: np.ndarray,
        target_twist: np.ndarray | None = None,
        obstacles: Obstacles | None = None,
    ) -> MpcPlan:
        """Plan from the measured configuration ``q0`` (every joint of the model, ``(n,)``) at ``start``.

        Args:
            q0: the measured configuration.
            start: its time (s, the robot's clock); the previous plan is shifted by the time since its own.
            world_T_target: the target's pose at ``start``, ``(4, 4)``.
            target_twist: its velocity (linear, angular; world frame), ``(6,)``; None: it stands still.
            obstacles: what the clearance frames keep clear of (None or empty: nothing).

        Raises:
            MotionError: the QP solver failed (the message says how).
        """
        import pinocchio as pin

        settings, m, n = self.settings, self._m, self._n
        dt = settings.timestep
        q0 = np.asarray(q0, dtype=float)
        cols = self._columns
        start_group = q0[cols]
        guess, velocity0 = self._warm_start(start, start_group)
        twist = np.zeros(6) if target_twist is None else np.asarray(target_twist, dtype=float)
        targets = target_path(world_T_target, twist, self._times)
        obstacles = obstacles if obstacles is not None and len(obstacles) else None
        size = n * m

        hessian = np.zeros((size, size))
        gradient = np.zeros(size)
        weights = np.array([settings.position_weight] * 3 + [settings.orientation_weight] * 3)
        rows_c: list[np.ndarray] = []
        lower_c: list[np.ndarray] = []
        upper_c: list[np.ndarray] = []
        pm, data = self.model.pin_model, self._data
        mimic = self.model.mimic_map
        q = q0.copy()
        cartesian_jacobians: list[np.ndarray] = []
        tracking: list[tuple[np.ndarray, np.ndarray]] = []
        for k in range(n):
            block = slice(k * m, (k + 1) * m)
            q[cols] = guess[k]
            pq = self.model.pin_configuration(q)
            pin.computeJointJacobians(pm, data, pq)
            pin.updateFramePlacements(pm, data)
            current_T_target = data.oMf[self._frame_id].actInv(pin.SE3(targets[k]))
            error = pin.log6(current_T_target).vector
            local = pin.getFrameJacobian(pm, data, self._frame_id, pin.ReferenceFrame.LOCAL)
            jacobian = (pin.Jlog6(current_T_target.inverse()) @ local @ mimic)[:, cols]
            # ||W (error - J (q_k - q̄_k))||² = ||A q_k - b||² with A = W J, b = W (error + J q̄_k).
            a = weights[:, None] * jacobian
            b = weights * (error + jacobian @ guess[k])
            hessian[block, block] += 2.0 * a.T @ a
            gradient[block] -= 2.0 * a.T @ b
            tracking.append((a, b))
            if self._cartesian_id is not None:
                cartesian_jacobians.append(self._linear_jacobian(self._cartesian_id, cols))
            if obstacles is not None and self._clearance_ids:
                row, low, push = self._clearance_rows(obstacles, guess[k], cols, k, size)
                gradient[block] -= push
                rows_c.append(row)
                lower_c.append(low)
                upper_c.append(np.full(len(low), np.inf))

        # Smoothness: velocity and acceleration penalties over the plan.
        c1 = np.zeros(n * m)
        c1[:m] = start_group
        c2 = np.zeros(n * m)
        c2[:m] = start_group + dt * velocity0  # q_1 - 2 q_0 + q_-1, with q_-1 = q_0 - dt v_0
        if n > 1:
            c2[m : 2 * m] = -start_group
        plan = slice(0, n * m)
        for weight, diff, offset, scale in (
            (settings.velocity_weight, self._d1, c1, dt),
            (settings.acceleration_weight, self._d2, c2, dt * dt),
        ):
            w = weight / (scale * scale)
            hessian[plan, plan] += 2.0 * w * diff.T @ diff
            gradient[plan] -= 2.0 * w * diff.T @ offset
        blocks: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        for name, diff, offset, limit in (
            ("velocity", self._d1, c1, np.tile(self._velocity_limit * dt, n)),
            ("acceleration", self._d2, c2, np.tile(self._acceleration_limit * dt * dt, n)),
        ):
            row = np.zeros((n * m, size))
            row[:, plan] = diff
            blocks[name] = (row, offset - limit, offset + limit)
        if cartesian_jacobians:
            bound = float(settings.max_cartesian_speed or 0.0) * dt / SPEED_POLYTOPE_REACH
            offsets = self._speed_offsets(cartesian_jacobians, start_group)
            blocks["cartesian speed"] = (
                self._speed_rows(cartesian_jacobians, size),
                offsets - bound,
                offsets + bound,
            )
        if rows_c:
            blocks["clearance"] = (np.vstack(rows_c), np.concatenate(lower_c), np.concatenate(upper_c))
        # A plan starting outside the limits (a measurement on the edge) may stay where it is.
        low_q = np.minimum(self.model.lower[cols], start_group)
        high_q = np.maximum(self.model.upper[cols], start_group)
        box = (np.tile(low_q, n), np.tile(high_q, n))
        hessian += 1e-9 * np.eye(size)
        positions = self._solve(hessian, gradient, list(blocks.values()), box)
        if positions is None:
            # The bounds can leave no plan: near a limit at speed (acceleration), or where the guess the
            # clearance is linearised at lies beyond what the joints can reach this step. Without the
            # acceleration bound and with the clearance relaxed to what holding still keeps, standing
            # still is a plan, so the QP has one.
            self.relaxed_steps += 1
            del blocks["acceleration"]
            if "clearance" in blocks:
                rows, lower, upper = blocks["clearance"]
                hold = rows @ np.tile(start_group, n)
                blocks["clearance"] = (rows, np.minimum(lower, hold), upper)
            positions = self._solve(hessian, gradient, list(blocks.values()), box)
        if positions is None:
            raise MotionError("the MPC's QP has no solution within the joint limits from this state")
        plan_positions = positions[: n * m].reshape(n, m)
        cost = sum(
            float(np.sum((a @ q_k - b) ** 2)) for (a, b), q_k in zip(tracking, plan_positions, strict=True)
        )
        previous = np.vstack((start_group[None], plan_positions[:-1]))
        velocities = (plan_positions - previous) / dt
        self._previous = (float(start), start_group, plan_positions, velocities)
        now_error = self._error_now(q0, world_T_target)
        clearance = self._clearance_at(q0, obstacles) if obstacles is not None else np.inf
        return MpcPlan(
            self.group.joint_names,
            float(start),
            self._times.copy(),
            plan_positions,
            velocities,
            float(cost),
            now_error[0],
            now_error[1],
            float(clearance),
        )

    # -- internals -------------------------------------------------------------------------------

    def _warm_start(self, start: float, start_group: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The previous plan shifted to ``start`` (or rest at ``start_group``), and its velocity then.

        The shifted plan is moved onto the measurement: its offset from ``start_group`` now fades out over
        the horizon, so the linearisation starts where the robot is.
        """
        n, dt = self._n, self.settings.timestep
        rest = np.repeat(start_group[None], n, axis=0), np.zeros(self._m)
        if self._previous is None:
            return rest
        before, q_before, positions, velocities = self._previous
        shift = round((start - before) / dt)
        if shift < 0 or shift >= n:
            return rest
        path = np.vstack((positions, np.repeat(positions[-1:], shift, axis=0)))[shift : shift + n]
        planned_now = positions[shift - 1] if shift > 0 else q_before
        velocity = velocities[max(shift - 1, 0)]
        fade = np.linspace(1.0, 0.0, n)[:, None]
        return path + fade * (start_group - planned_now), velocity

    def _linear_jacobian(self, frame_id: int, cols: np.ndarray) -> np.ndarray:
        """The linear Jacobian ``(3, m)`` of a frame in world axes (joint Jacobians already computed)."""
        import pinocchio as pin

        jacobian = pin.getFrameJacobian(
            self.model.pin_model, self._data, frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        )
        return (jacobian[:3] @ self.model.mimic_map)[:, cols]

    def _speed_rows(self, jacobians: list[np.ndarray], size: int) -> np.ndarray:
        """Rows giving ``n_i · J_k (q_k - q_{k-1})`` for each direction and step."""
        m, directions = self._m, len(_DIRECTIONS)
        rows = np.zeros((directions * len(jacobians), size))
        for k, jacobian in enumerate(jacobians):
            projected = _DIRECTIONS @ jacobian
            rows[k * directions : (k + 1) * directions, k * m : (k + 1) * m] = projected
            if k > 0:
                rows[k * directions : (k + 1) * directions, (k - 1) * m : k * m] = -projected
        return rows

    def _speed_offsets(self, jacobians: list[np.ndarray], start_group: np.ndarray) -> np.ndarray:
        """The constant part of the speed rows: ``n_i · J_0 q_0`` for the first step, 0 after."""
        offsets = np.zeros(len(_DIRECTIONS) * len(jacobians))
        offsets[: len(_DIRECTIONS)] = _DIRECTIONS @ jacobians[0] @ start_group
        return offsets

    def _clearance_rows(
        self, obstacles: Obstacles, guess: np.ndarray, cols: np.ndarray, step: int, size: int
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The clearance constraints of one step, linearised at the step's guess ``q̄_k``.

        For each clearance frame and each of its nearest obstacles: ``d(q̄_k) + ∇d (q_k - q̄_k) >=
        min(safe_distance, d(q̄_k))``: never closer than ``safe_distance``, and where the guess is already
        closer, no closer than that (so the QP stays feasible). Inside the clearance a linear cost pushes
        away (returned as the gradient to subtract), so the robot moves out as fast as tracking lets it.

        Returns:
            rows ``(F*K, size)``, their lower bounds (-inf for unused rows) and the push ``(m,)``.
        """
        settings, m = self.settings, self._m
        rows = np.zeros((len(self._clearance_ids) * NEAREST_OBSTACLES, size))
        lower = np.full(len(rows), -np.inf)
        push = np.zeros(m)
        for f, frame_id in enumerate(self._clearance_ids):
            point = np.asarray(self._data.oMf[frame_id].translation)
            index, distance = obstacles.nearest(point, NEAREST_OBSTACLES)
            jacobian = self._linear_jacobian(frame_id, cols)
            for j, (i, d) in enumerate(zip(index, distance, strict=True)):
                away = point - obstacles.centres[i]
                length = float(np.linalg.norm(away))
                if length < 1e-9:
                    continue  # on the centre: no direction to move away along
                grad = (away / length) @ jacobian
                r = f * NEAREST_OBSTACLES + j
                rows[r, step * m : (step + 1) * m] = grad
                lower[r] = min(settings.safe_distance, float(d)) - float(d) + grad @ guess
                if d < settings.safe_distance:
                    push += CLEARANCE_PUSH * grad
        return rows, lower, push

    def _solve(
        self,
        hessian: np.ndarray,
        gradient: np.ndarray,
        blocks: list[tuple[np.ndarray, np.ndarray, np.ndarray]],
        box: tuple[np.ndarray, np.ndarray],
    ) -> np.ndarray | None:
        """ProxQP on ``0.5 x'Hx + g'x`` with ``lower <= rows x <= upper`` per block and the box.

        The solver object is kept while the problem keeps its size (no reallocation per step); each solve
        starts cold, with its scaling recomputed for the new rows (see the module docstring).
        """
        from proxsuite import proxqp

        inf = 1e20  # ProxQP's infinity
        rows = np.vstack([b[0] for b in blocks])
        lower = np.maximum(np.concatenate([b[1] for b in blocks]), -inf)
        upper = np.minimum(np.concatenate([b[2] for b in blocks]), inf)
        lower_box, upper_box = np.maximum(box[0], -inf), np.minimum(box[1], inf)
        shape = (len(gradient), len(rows))
        qp = self._qp if self._qp is not None and self._qp_shape == shape else None
        if qp is None:
            qp = proxqp.dense.QP(shape[0], 0, shape[1], True)
            qp.settings.eps_abs = 1e-5
            qp.settings.max_iter = 400
            qp.settings.initial_guess = proxqp.InitialGuess.EQUALITY_CONSTRAINED_INITIAL_GUESS
            qp.init(hessian, gradient, None, None, rows, lower, upper, lower_box, upper_box)
            self._qp, self._qp_shape = qp, shape
        else:
            qp.update(
                hessian,
                gradient,
                None,
                None,
                rows,
                lower,
                upper,
                lower_box,
                upper_box,
                update_preconditioner=True,
            )
        qp.solve()
        if qp.results.info.status != proxqp.QPSolverOutput.PROXQP_SOLVED:
            self._qp = None  # start afresh next time
            return None
        return np.array(qp.results.x)

    def _error_now(self, q0: np.ndarray, world_T_target: np.ndarray) -> tuple[float, float]:
        import pinocchio as pin

        pin.framesForwardKinematics(self.model.pin_model, self._data, self.model.pin_configuration(q0))
        world_T_frame = np.array(self._data.oMf[self._frame_id].homogeneous)
        target = np.asarray(world_T_target, dtype=float)
        position = float(np.linalg.norm(world_T_frame[:3, 3] - target[:3, 3]))
        return position, transforms.rotation_angle(world_T_frame[:3, :3], target[:3, :3])

    def _clearance_at(self, q0: np.ndarray, obstacles: Obstacles) -> float:
        """Distance of the nearest clearance frame to an obstacle at ``q0`` (frames placed by _error_now)."""
        return min(
            (obstacles.distance(np.asarray(self._data.oMf[i].translation)) for i in self._clearance_ids),
            default=float("inf"),
        )
