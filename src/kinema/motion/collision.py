"""Collision checking of the robot against itself and the planning scene (coal through pinocchio).

Self-collision pairs are every pair of robot links that can move relative to each other, minus the pairs
the SRDF disables. Robot-scene pairs carry the ``padding`` as a safety margin, so the robot keeps that
distance from obstacles while self-collision stays exact (padding links against each other would make
folded but valid poses, and the gripper's own fingers, "collide").

Objects attached to a link (:class:`~kinema.motion.planning_scene.AttachedObject`) ride on that link's
joint: they are checked against the world (padded, as the robot is), against the robot's links other than
their own link and its touch links (exact, as self-collision is), and against other attached objects.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from kinema.errors import MotionError
from kinema.motion.planning_scene import CollisionObject, PlanningScene

if TYPE_CHECKING:
    from kinema.motion.robot_model import RobotModel


def _coal_shape(obj: CollisionObject):
    import coal

    if obj.shape == "box":
        return coal.Box(*(2 * np.asarray(obj.size, dtype=float)))
    if obj.shape == "cylinder":
        return coal.Cylinder(float(obj.size[0]), 2 * float(obj.size[1]))
    if obj.shape == "capsule":
        return coal.Capsule(float(obj.size[0]), 2 * float(obj.size[1]))
    return coal.Sphere(float(obj.size[0]))


class CollisionChecker:
    """Answers "is configuration ``q`` in collision?" for one robot model and one planning scene.

    Not thread-safe (it owns pinocchio scratch data); make one per thread. Changes to the scene are
    picked up on the next check (the scene's ``version`` is compared). Pairs in
    :attr:`allowed_collisions` (a link and a scene object, or two links) are not checked, as MoveIt's
    allowed collision matrix does for a gripper closing on the object it grasps.

    Args:
        model: the robot model (its URDF collision geometry is used).
        scene: obstacles; an empty scene when omitted.
        padding: safety distance (m) kept between robot links and scene objects.
    """

    def __init__(self, model: RobotModel, scene: PlanningScene | None = None, padding: float = 0.0) -> None:
        self.model = model
        self.scene = scene if scene is not None else PlanningScene()
        self._padding = float(padding)
        self._robot_geoms = model.collision_geometry().copy()  # shares the model's shapes
        self._data = model.new_data()
        self._scene_version = -1
        self._allowed: frozenset[frozenset[str]] = frozenset()
        self._build()

    @property
    def padding(self) -> float:
        """Safety distance (m) between robot and scene objects."""
        return self._padding

    @padding.setter
    def padding(self, value: float) -> None:
        if value < 0:
            raise MotionError(f"link padding must be >= 0 m, got {value}")
        self._padding = float(value)
        for k in self._scene_pairs:
            self._geom_data.collisionRequests[k].security_margin = self._padding

    def _link_of(self, geom_index: int) -> str:
        """The robot link (or scene object) a geometry belongs to."""
        geom = self._geom_model.geometryObjects[geom_index]
        return geom.name if geom_index >= self._n_robot else self._link_of_obj(geom)

    def _build(self) -> None:
        import pinocchio as pin

        gm = self._robot_geoms.copy()
        self._n_robot = gm.ngeoms
        for obj in self.scene.objects.values():
            placement = pin.SE3(np.asarray(obj.world_T_object, dtype=float))
            gm.addGeometryObject(pin.GeometryObject(obj.name, 0, 0, placement, _coal_shape(obj)))
        n_world = gm.ngeoms
        # attached shape index -> (its object's link, the links it may touch)
        carried: dict[int, tuple[str, frozenset[str]]] = {}
        pin_model = self.model.pin_model
        for attached in self.scene.attached_objects().values():
            if not pin_model.existFrame(attached.link):
                raise MotionError(
                    f"collision object {attached.object_id!r} is attached to {attached.link!r}, which is no "
                    "link of the robot"
                )
            frame_id = self.model.frame_id(attached.link)
            frame = pin_model.frames[frame_id]
            joint_T_link = np.asarray(frame.placement.homogeneous)
            for shape in attached.primitives:
                placement = pin.SE3(joint_T_link @ np.asarray(shape.world_T_object, dtype=float))
                carried[gm.ngeoms] = (attached.link, attached.touch_links | {attached.link})
                gm.addGeometryObject(
                    pin.GeometryObject(shape.name, frame.parentJoint, frame_id, placement, _coal_shape(shape))
                )
        semantic = self.model.semantic
        robot = list(range(self._n_robot))
        scene_pairs = []
        for a in robot:
            ga = gm.geometryObjects[a]
            for b in robot[a + 1 :]:
                gb = gm.geometryObjects[b]
                if ga.parentJoint == gb.parentJoint:
                    continue  # rigidly attached: their distance never changes
                if semantic.collision_disabled(self._link_of_obj(ga), self._link_of_obj(gb)):
                    continue
                gm.addCollisionPair(pin.CollisionPair(a, b))
            if ga.parentJoint == 0:
                continue  # fixed to the world, like the scene
            for b in range(self._n_robot, n_world):
                scene_pairs.append(len(gm.collisionPairs))
                gm.addCollisionPair(pin.CollisionPair(a, b))
        for c, (_, touching) in carried.items():
            gc = gm.geometryObjects[c]
            if gc.parentJoint == 0:
                continue  # carried by a link fixed to the world: part of the scene
            for b in range(self._n_robot, n_world):
                scene_pairs.append(len(gm.collisionPairs))
                gm.addCollisionPair(pin.CollisionPair(c, b))
            for a in robot:
                ga = gm.geometryObjects[a]
                if ga.parentJoint != gc.parentJoint and self._link_of_obj(ga) not in touching:
                    gm.addCollisionPair(pin.CollisionPair(a, c))
            for d in carried:
                if d > c and gm.geometryObjects[d].parentJoint != gc.parentJoint:
                    gm.addCollisionPair(pin.CollisionPair(c, d))
        self._carried = sorted(carried)
        self._geom_model = gm
        self._geom_data = pin.GeometryData(gm)
        self._scene_pairs = scene_pairs
        for k in scene_pairs:
            self._geom_data.collisionRequests[k].security_margin = self._padding
        self._pair_names = [
            frozenset((self._link_of(pair.first), self._link_of(pair.second))) for pair in gm.collisionPairs
        ]
        self._apply_allowed()
        self._scene_version = self.scene.version

    @property
    def allowed_collisions(self) -> frozenset[frozenset[str]]:
        """Pairs of names (robot links, scene object names) whose contact is allowed: never checked."""
        return self._allowed

    @allowed_collisions.setter
    def allowed_collisions(self, pairs: Iterable[Iterable[str]]) -> None:
        allowed = frozenset(frozenset(pair) for pair in pairs)
        if allowed != self._allowed:
            self._allowed = allowed
            self._apply_allowed()

    def _apply_allowed(self) -> None:
        for k, names in enumerate(self._pair_names):
            if names in self._allowed:
                self._geom_data.deactivateCollisionPair(k)
            else:
                self._geom_data.activateCollisionPair(k)

    def _link_of_obj(self, geom) -> str:
        return self.model.pin_model.frames[geom.parentFrame].name

    @property
    def pair_count(self) -> int:
        """Number of geometry pairs each check tests."""
        return len(self._geom_model.collisionPairs)

    def in_collision(self, q: np.ndarray) -> bool:
        """True when configuration ``q`` (shape ``(n,)``) touches itself or the scene (within the padding)."""
        import pinocchio as pin

        if self.scene.version != self._scene_version:
            self._build()
        return bool(
            pin.computeCollisions(
                self.model.pin_model,
                self._data,
                self._geom_model,
                self._geom_data,
                self.model.pin_configuration(np.asarray(q, dtype=float)),
                True,
            )
        )

    def is_valid(self, q: np.ndarray) -> bool:
        """True when ``q`` is inside the joint limits and collision-free."""
        return self.model.within_limits(q) and not self.in_collision(q)

    def colliding_pairs(self, q: np.ndarray) -> list[tuple[str, str]]:
        """All colliding pairs at ``q`` as (link or object, link or object) names, for error messages."""
        import pinocchio as pin

        if self.scene.version != self._scene_version:
            self._build()
        pin.computeCollisions(
            self.model.pin_model,
            self._data,
            self._geom_model,
            self._geom_data,
            self.model.pin_configuration(np.asarray(q, dtype=float)),
            False,
        )
        pairs = []
        active = self._geom_data.activeCollisionPairs
        for k, pair in enumerate(self._geom_model.collisionPairs):
            if active[k] and self._geom_data.collisionResults[k].isCollision():
                names = (self._link_of(pair.first), self._link_of(pair.second))
                if names not in pairs:
                    pairs.append(names)
        return pairs

    def robot_bounds(self, q: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """World-axis-aligned bounds ``(lower, upper)`` of each robot collision geometry at ``q`` (m), the
        shapes of the objects it carries included.

        Loose for tilted shapes; meant for filtering the robot out of what its cameras see.
        """
        import pinocchio as pin

        if self.scene.version != self._scene_version:
            self._build()
        pin.updateGeometryPlacements(
            self.model.pin_model,
            self._data,
            self._geom_model,
            self._geom_data,
            self.model.pin_configuration(np.asarray(q, dtype=float)),
        )
        bounds = []
        for index in [*range(self._n_robot), *self._carried]:
            geometry = self._geom_model.geometryObjects[index].geometry
            geometry.computeLocalAABB()
            box = geometry.aabb_local
            lower, upper = np.asarray(box.min_), np.asarray(box.max_)
            centre, half = (lower + upper) / 2, (upper - lower) / 2
            placement = self._geom_data.oMg[index]
            world_centre = placement.rotation @ centre + placement.translation
            reach = np.abs(placement.rotation) @ half
            bounds.append((world_centre - reach, world_centre + reach))
        return bounds

    def describe(self, q: np.ndarray) -> str:
        """A short sentence naming what collides at ``q`` ("wrist_3_link - table, ...")."""
        pairs = self.colliding_pairs(q)
        if not pairs:
            return "no collision"
        return ", ".join(f"{a} - {b}" for a, b in pairs[:4]) + (
            f" (+{len(pairs) - 4} more)" if len(pairs) > 4 else ""
        )

    def first_invalid(self, path: np.ndarray, max_step: float = 0.01) -> int | None:
        """Check a piecewise-linear joint path at a resolution of ``max_step`` (rad or m per joint).

        Args:
            path: configurations, shape ``(N, n)``.
            max_step: largest change of any joint between two checked configurations.

        Returns:
            The index of the segment (0-based, the segment from ``path[i]`` to ``path[i+1]``; ``N-1`` for a
            lone last point) containing the first invalid configuration, or None when the path is valid.
        """
        path = np.asarray(path, dtype=float)
        if not self.is_valid(path[0]):
            return 0
        for i in range(len(path) - 1):
            a, b = path[i], path[i + 1]
            steps = max(1, int(np.ceil(np.abs(b - a).max() / max_step)))
            for s in range(1, steps + 1):
                if not self.is_valid(a + (b - a) * (s / steps)):
                    return i
        return None


def self_collisions(checker: CollisionChecker, positions: Mapping[str, float]) -> list[tuple[str, str]]:
    """The pairs of the robot's links in collision at ``positions`` (joint values by name; the model's
    other joints at their neutral value, names it does not know left out), the pairs the checker allows
    not counted: where a named state (a waypoint, ``Home``) leaves the planner no start or goal."""
    model = checker.model
    known = set(model.joint_names)
    q = model.configuration({name: value for name, value in positions.items() if name in known})
    return checker.colliding_pairs(q)


def self_collision_warning(what: str, pairs: Sequence[tuple[str, str]], srdf: str) -> str:
    """``what`` (a waypoint, ``Home``) is in self-collision with the link ``pairs``, and what to add to
    ``srdf`` if they touch by design: one ``<disable_collisions>`` each (reason ``Default``, as MoveIt's
    setup assistant names a pair in collision in the default state)."""
    overlaps = ", ".join(f"{first} - {second}" for first, second in pairs)
    elements = " ".join(
        f'<disable_collisions link1="{first}" link2="{second}" reason="Default"/>' for first, second in pairs
    )
    them = "the pair" if len(pairs) == 1 else "the pairs"
    return (
        f"{what} is in self-collision ({overlaps}): no motion can start or end there. If these links touch "
        f"by design, disable {them} in {srdf}: {elements}"
    )
