"""A seeded RRT-Connect: the same start, goal, scene and seed give the same path, in any process.

OMPL (the planner behind :func:`kinema.motion.planner.plan_joint_goal`) draws its random numbers from one
process-wide generator that can be seeded only once, before the first plan: a second plan with "the same
seed" in a running runtime continues that generator and may find another path. The ``ompl`` wheel's Python
bindings offer no way around it (a planner's sampler cannot be replaced or reseeded from Python). MoveIt
Pro's task stages take a ``seed`` and a ``max_iterations`` for their RRT, so reproducibility per plan is
part of their contract; this planner provides it.

Everything random comes from one ``numpy`` generator seeded per plan, the search is bounded by iterations
(a timeout only turns a slow search into a failure, never into another answer), and the path is shortened
by a fixed number of seeded shortcut attempts. States are configurations of the planning group's joints;
``valid(q)`` and the segment checks work on those.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from kinema.errors import MotionError


@dataclass(frozen=True)
class RrtOptions:
    """Tuning of :func:`rrt_connect`.

    Attributes:
        seed: seed of the search and of the shortcuts.
        max_iterations: samples drawn before the search gives up (each grows one tree and tries to connect
            the other to it).
        timeout: seconds before the search gives up; a search that ends in time gives the same path
            however long it took.
        max_step: collision-check resolution: largest joint change (rad or m) between checked states.
        extend_fraction: the longest tree edge, as a fraction of the joint space's diagonal (OMPL's
            RRTConnect default range is 0.2 of the space's extent).
        shortcut_attempts: random shortcuts tried on the found path (pairs of points on it joined by a
            straight segment when that segment is free).
    """

    seed: int = 0
    max_iterations: int = 5000
    timeout: float = 1.0
    max_step: float = 0.02
    extend_fraction: float = 0.2
    shortcut_attempts: int = 60

    def __post_init__(self) -> None:
        if self.max_iterations < 1:
            raise MotionError(f"max_iterations must be at least 1, got {self.max_iterations}")
        if not self.timeout > 0:
            raise MotionError(f"the planning timeout must be positive, got {self.timeout} s")
        if not self.max_step > 0:
            raise MotionError(f"the collision-check step must be positive, got {self.max_step}")


class _Tree:
    """Nodes (rows of a growing array) with their parents; nearest-neighbour by brute force."""

    def __init__(self, root: np.ndarray, capacity: int) -> None:
        self.rooted_at = root
        self.nodes = np.empty((capacity, len(root)))
        self.nodes[0] = root
        self.parents = [-1]

    def __len__(self) -> int:
        return len(self.parents)

    def nearest(self, q: np.ndarray) -> int:
        diff = self.nodes[: len(self)] - q
        return int(np.argmin(np.einsum("ij,ij->i", diff, diff)))

    def add(self, q: np.ndarray, parent: int) -> int:
        if len(self) == len(self.nodes):
            self.nodes = np.vstack((self.nodes, np.empty_like(self.nodes)))
        self.nodes[len(self)] = q
        self.parents.append(parent)
        return len(self) - 1

    def branch(self, index: int) -> list[np.ndarray]:
        """The states from the root to node ``index``."""
        states = []
        while index >= 0:
            states.append(self.nodes[index].copy())
            index = self.parents[index]
        return states[::-1]


def _segment_free(valid: Callable[[np.ndarray], bool], a: np.ndarray, b: np.ndarray, max_step: float) -> bool:
    """Whether every state on the straight segment ``a``-``b`` is valid, ``b`` included (``a`` is known).

    The end is checked first, then the interior coarse to fine (bisection order), so a blocked segment is
    usually found after few checks.
    """
    steps = max(1, int(np.ceil(np.abs(b - a).max() / max_step)))
    if not valid(b):
        return False
    checked = {0, steps}
    stride = steps
    while stride > 1:
        half = stride // 2
        for s in range(half, steps, stride):
            if s not in checked:
                checked.add(s)
                if not valid(a + (b - a) * (s / steps)):
                    return False
        stride = half
    for s in range(1, steps):
        if s not in checked and not valid(a + (b - a) * (s / steps)):
            return False
    return True


def rrt_connect(
    valid: Callable[[np.ndarray], bool],
    start: np.ndarray,
    goal: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    options: RrtOptions | None = None,
) -> np.ndarray:
    """Find a collision-free path from ``start`` to ``goal`` with a bidirectional RRT, then shorten it.

    Args:
        valid: whether a configuration of the group's joints, shape ``(k,)``, is collision-free.
        start: the group's start, ``(k,)``; valid.
        goal: the group's goal, ``(k,)``; valid.
        lower: the joints' lower limits, ``(k,)`` (finite).
        upper: the joints' upper limits, ``(k,)`` (finite).
        options: seed, iteration cap, timeout, resolution.

    Returns:
        The path's waypoints, ``(m, k)``: the first row is ``start``, the last ``goal``, and every straight
        segment between neighbours is free at ``options.max_step``.

    Raises:
        MotionError: no path within ``max_iterations`` samples or within the timeout.
    """
    opts = options or RrtOptions()
    start = np.asarray(start, dtype=float)
    goal = np.asarray(goal, dtype=float)
    lower = np.asarray(lower, dtype=float)
    upper = np.asarray(upper, dtype=float)
    if not (np.all(np.isfinite(lower)) and np.all(np.isfinite(upper))):
        raise MotionError("the seeded RRT-Connect needs finite joint limits to sample between")
    rng = np.random.default_rng(opts.seed)
    deadline = time.monotonic() + opts.timeout
    if _segment_free(valid, start, goal, opts.max_step):
        return np.array([start, goal])
    reach = opts.extend_fraction * float(np.linalg.norm(upper - lower))
    capacity = min(opts.max_iterations, 1024) + 1
    grow, other = _Tree(start, capacity), _Tree(goal, capacity)
    for _ in range(opts.max_iterations):
        if time.monotonic() > deadline:
            raise MotionError(
                f"no collision-free path found within {opts.timeout:.2f} s "
                f"(seeded RRT-Connect, {len(grow) + len(other)} states explored)"
            )
        added = _extend(grow, rng.uniform(lower, upper), valid, reach, opts.max_step)
        if added is not None:
            met = _connect(other, grow.nodes[added], valid, reach, opts.max_step)
            if met is not None:
                ours, theirs = grow.branch(added), other.branch(met)
                # Each branch starts at its tree's root; the trees take turns growing.
                from_start, from_goal = (ours, theirs) if grow.rooted_at is start else (theirs, ours)
                path = np.array(from_start + from_goal[::-1][1:])
                return _shortcut(path, valid, opts, rng)
        grow, other = other, grow
    raise MotionError(
        f"no collision-free path found in {opts.max_iterations} iterations (seeded RRT-Connect, seed "
        f"{opts.seed}); raise max_iterations, or the goal may be enclosed by obstacles"
    )


def _toward(tree: _Tree, target: np.ndarray, reach: float) -> tuple[int, np.ndarray, bool]:
    near = tree.nearest(target)
    origin = tree.nodes[near]
    gap = float(np.linalg.norm(target - origin))
    if gap <= reach:
        return near, target.copy(), True
    return near, origin + (target - origin) * (reach / gap), False


def _extend(
    tree: _Tree, target: np.ndarray, valid: Callable[[np.ndarray], bool], reach: float, max_step: float
) -> int | None:
    near, new, _ = _toward(tree, target, reach)
    if not _segment_free(valid, tree.nodes[near], new, max_step):
        return None
    return tree.add(new, near)


def _connect(
    tree: _Tree, target: np.ndarray, valid: Callable[[np.ndarray], bool], reach: float, max_step: float
) -> int | None:
    """Grow ``tree`` toward ``target`` step by step; the node at ``target`` when it got there."""
    while True:
        near, new, arrives = _toward(tree, target, reach)
        if not _segment_free(valid, tree.nodes[near], new, max_step):
            return None
        index = tree.add(new, near)
        if arrives:
            return index


def _skip_waypoints(path: np.ndarray, valid: Callable[[np.ndarray], bool], max_step: float) -> np.ndarray:
    """From each kept waypoint, jump to the farthest later one a free straight segment reaches."""
    points = [path[0]]
    i = 0
    while i < len(path) - 1:
        j = len(path) - 1
        while j > i + 1 and not _segment_free(valid, path[i], path[j], max_step):
            j -= 1
        points.append(path[j])
        i = j
    return np.array(points)


def _shortcut(
    path: np.ndarray, valid: Callable[[np.ndarray], bool], opts: RrtOptions, rng: np.random.Generator
) -> np.ndarray:
    """Shorten ``path``: skip waypoints, try random shortcuts between points anywhere on it (not only
    waypoints; each that is free is kept), then skip waypoints again."""
    path = _skip_waypoints(path, valid, opts.max_step)
    for _ in range(opts.shortcut_attempts):
        if len(path) < 3:
            break
        lengths = np.linalg.norm(np.diff(path, axis=0), axis=1)
        cumulative = np.concatenate(([0.0], np.cumsum(lengths)))
        at = np.sort(rng.uniform(0.0, cumulative[-1], 2))
        seg = np.clip(np.searchsorted(cumulative, at, side="right") - 1, 0, len(lengths) - 1)
        if seg[0] == seg[1]:
            continue
        ends = [
            path[s] + (path[s + 1] - path[s]) * ((a - cumulative[s]) / max(lengths[s], 1e-12))
            for s, a in zip(seg, at, strict=True)
        ]
        if not _segment_free(valid, ends[0], ends[1], opts.max_step):
            continue
        path = np.vstack((path[: seg[0] + 1], ends[0], ends[1], path[seg[1] + 1 :]))
        # An end that landed on a waypoint adds nothing: drop zero-length segments.
        keep = np.concatenate(([True], np.linalg.norm(np.diff(path, axis=0), axis=1) > 1e-9))
        path = path[keep]
    return _skip_waypoints(path, valid, opts.max_step)
