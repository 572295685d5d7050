"""The planning scene: collision objects in the world the robot must not touch (table, tray, walls, ...).

Three kinds of objects live in it. The *environment* is what the config's cell is made of (the static
geoms of its MuJoCo scene); it is always there. *World objects* are what objectives add at run time
(``AddCollisionBox``, ``AddCollisionObject``, ``AddURDF``), each under an id as in MoveIt, made of one or
more primitives. *Attached objects* are world objects bound to a robot link (``AttachURDF``): they move
with the link, the planner checks them against the world and the robot's other links, and detaching puts
them back into the world where they are then. An object is in the world or attached, never both.
:meth:`PlanningScene.reset_world` removes world and attached objects and leaves the environment. Planning
checks all three; listeners (the runtime's publisher for ``kinema view``) hear of every change.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import kinema.mujoco_gl  # noqa: F401  (MuJoCo's OpenGL backend is chosen before the lazy mujoco imports below)
from kinema.errors import MotionError, did_you_mean

SHAPES = ("box", "cylinder", "sphere", "capsule")


@dataclass(frozen=True, eq=False)  # holds numpy arrays: compare fields explicitly
class CollisionObject:
    """One primitive obstacle.

    Attributes:
        name: unique name in the scene.
        shape: one of ``box``, ``cylinder``, ``sphere``, ``capsule``.
        size: ``box``: half extents (x, y, z); ``cylinder``/``capsule``: (radius, half length along z);
            ``sphere``: (radius,). Metres.
        world_T_object: pose of the object's centre, shape ``(4, 4)``.
    """

    name: str
    shape: str
    size: tuple[float, ...]
    world_T_object: np.ndarray


_SIZE_COUNTS = {"box": 3, "cylinder": 2, "capsule": 2, "sphere": 1}


def check_shape(obj: CollisionObject) -> None:
    """Raise :class:`MotionError` unless ``obj`` has a known shape, the right sizes and a finite pose."""
    if obj.shape not in _SIZE_COUNTS:
        raise MotionError(
            f"unknown collision shape {obj.shape!r} for {obj.name!r}; {did_you_mean(obj.shape, SHAPES)}"
        )
    if len(obj.size) != _SIZE_COUNTS[obj.shape]:
        raise MotionError(
            f"a {obj.shape} needs {_SIZE_COUNTS[obj.shape]} size values, {obj.name!r} has {len(obj.size)}"
        )
    if not all(np.isfinite(v) and v >= 0 for v in obj.size):
        raise MotionError(f"the sizes of {obj.name!r} must be finite and >= 0 m, got {list(obj.size)}")
    if np.shape(obj.world_T_object) != (4, 4) or not np.all(np.isfinite(obj.world_T_object)):
        raise MotionError(f"the pose of {obj.name!r} must be a finite 4x4 transform")


@dataclass(frozen=True, eq=False)  # holds numpy arrays
class AttachedObject:
    """A world object bound to a robot link (MoveIt's ``AttachedCollisionObject``).

    Attributes:
        object_id: its id.
        link: the robot link it moves with.
        primitives: its shapes; each ``world_T_object`` is the shape's pose in the *link's* frame
            (``link_T_shape``), and each name is its name in collision reports (the id, or ``id/k``).
        link_T_object: the object's own pose in the link's frame.
        touch_links: robot links it may touch (the link itself always may).
        urdf: it was added from a URDF (``AddURDF``).
    """

    object_id: str
    link: str
    primitives: tuple[CollisionObject, ...]
    link_T_object: np.ndarray
    touch_links: frozenset[str] = frozenset()
    urdf: bool = False


@dataclass
class PlanningScene:
    """The obstacles planning checks against, by name. ``version`` changes whenever the scene does.

    Attributes:
        objects: every primitive fixed in the world (environment and world objects), by unique name.
        world: the world objects added at run time: id -> names of its primitives in :attr:`objects`.
        version: incremented on every change.
        world_poses: each world object's own pose (MoveIt's ``CollisionObject.pose``), in the world; a
            MOVE carries its primitives along with it.
        attached: the objects bound to robot links, by id (see :class:`AttachedObject`).
        urdf_ids: the ids of objects (in the world or attached) added from a URDF.
    """

    objects: dict[str, CollisionObject] = field(default_factory=dict)
    version: int = 0
    world: dict[str, tuple[str, ...]] = field(default_factory=dict)
    world_poses: dict[str, np.ndarray] = field(default_factory=dict)
    attached: dict[str, AttachedObject] = field(default_factory=dict)
    urdf_ids: set[str] = field(default_factory=set)
    _listeners: list[Callable[[PlanningScene], None]] = field(default_factory=list, repr=False)
    _lock: threading.RLock = field(default_factory=threading.RLock, repr=False)

    def add(self, obj: CollisionObject) -> None:
        """Add or replace an environment primitive.

        Raises:
            MotionError: unknown shape or wrong number of size values.
        """
        check_shape(obj)
        with self._lock:
            self.objects[obj.name] = obj
            self.version += 1
        self._changed()

    # -- world objects -----------------------------------------------------------------------------

    def add_world_object(
        self,
        object_id: str,
        primitives: Sequence[CollisionObject],
        *,
        replace: bool = True,
        pose: np.ndarray | None = None,
        urdf: bool = False,
    ) -> None:
        """Add world object ``object_id`` made of ``primitives`` (their names are ignored).

        Args:
            object_id: the object's id (MoveIt's ``CollisionObject.id``).
            primitives: its shapes, each placed in the world.
            replace: replace an object of the same id; when False an existing id is an error.
            pose: the object's own pose in the world (identity by default); :meth:`move_world_object`
                moves the primitives with it.
            urdf: the object comes from a URDF (``AddURDF``); replacing it by a plain object clears this.

        Raises:
            MotionError: empty id, no primitive, a bad shape, an id taken by the environment, an id
                attached to the robot, or an existing id without ``replace``.
        """
        if not object_id:
            raise MotionError("a collision object needs a non-empty id")
        if not primitives:
            raise MotionError(f"collision object {object_id!r} has no shape")
        with self._lock:
            self._refuse_attached(object_id, "replace")
            if object_id in self.world and not replace:
                raise MotionError(
                    f"collision object {object_id!r} is already in the planning scene "
                    "(overwrite it to replace it)"
                )
            self._store(object_id, list(primitives), np.eye(4) if pose is None else pose)
            if urdf:
                self.urdf_ids.add(object_id)
            else:
                self.urdf_ids.discard(object_id)
        self._changed()

    def _refuse_attached(self, object_id: str, what: str) -> None:
        """Raise when ``object_id`` is attached (the caller holds the lock)."""
        if object_id in self.attached:
            raise MotionError(
                f"collision object {object_id!r} is attached to {self.attached[object_id].link!r}; detach "
                f"it before you {what} it"
            )

    def append_to_world_object(
        self, object_id: str, primitives: Sequence[CollisionObject], pose: np.ndarray | None = None
    ) -> None:
        """Add ``primitives`` to world object ``object_id`` (MoveIt's APPEND); a new id is created.

        Args:
            object_id: the object's id.
            primitives: the shapes to add, each placed in the world.
            pose: the object's pose when it is created here (an existing object keeps its own).

        Raises:
            MotionError: empty id, no primitive, a bad shape or an id taken by the environment.
        """
        if not object_id:
            raise MotionError("a collision object needs a non-empty id")
        if not primitives:
            raise MotionError(f"collision object {object_id!r}: APPEND needs at least one shape")
        with self._lock:
            self._refuse_attached(object_id, "append to")
            before = [self.objects[n] for n in self.world.get(object_id, ())]
            own = self.world_poses.get(object_id, np.eye(4) if pose is None else pose)
            self._store(object_id, [*before, *primitives], own)
        self._changed()

    def move_world_object(self, object_id: str, world_T_object: np.ndarray) -> None:
        """Put world object ``object_id`` at ``world_T_object``, its primitives moving rigidly with it
        (MoveIt's MOVE).

        Raises:
            MotionError: no such world object (the message lists those there are), or a non-finite pose.
        """
        target = np.asarray(world_T_object, dtype=float)
        if target.shape != (4, 4) or not np.all(np.isfinite(target)):
            raise MotionError(f"the new pose of {object_id!r} must be a finite 4x4 transform")
        with self._lock:
            self._refuse_attached(object_id, "move")
            if object_id not in self.world:
                raise MotionError(
                    f"no collision object {object_id!r} in the planning scene to move; "
                    f"{did_you_mean(object_id, self.world)}"
                )
            delta = target @ np.linalg.inv(self.world_poses.get(object_id, np.eye(4)))
            moved = [
                CollisionObject(p.name, p.shape, p.size, delta @ p.world_T_object)
                for p in (self.objects[n] for n in self.world[object_id])
            ]
            self._store(object_id, moved, target)
        self._changed()

    def world_object_pose(self, object_id: str) -> np.ndarray | None:
        """The own pose of world object ``object_id`` (None when there is no such object)."""
        with self._lock:
            pose = self.world_poses.get(object_id) if object_id in self.world else None
            return None if pose is None else pose.copy()

    def _store(self, object_id: str, primitives: list[CollisionObject], pose: np.ndarray) -> None:
        """Replace world object ``object_id`` by ``primitives`` at ``pose`` (the caller holds the lock)."""
        names = [object_id] if len(primitives) == 1 else [f"{object_id}/{k}" for k in range(len(primitives))]
        placed = [
            CollisionObject(
                name, p.shape, tuple(float(v) for v in p.size), np.asarray(p.world_T_object, float)
            )
            for name, p in zip(names, primitives, strict=True)
        ]
        for obj in placed:
            check_shape(obj)
        own = np.asarray(pose, dtype=float)
        if own.shape != (4, 4) or not np.all(np.isfinite(own)):
            raise MotionError(f"the pose of {object_id!r} must be a finite 4x4 transform")
        old = self.world.get(object_id, ())
        taken = [n for n in names if n in self.objects and n not in old]
        if taken:
            raise MotionError(
                f"collision object id {object_id!r} is the name of part of the cell's environment; "
                "pick another id"
            )
        for name in old:
            self.objects.pop(name, None)
        for obj in placed:
            self.objects[obj.name] = obj
        self.world[object_id] = tuple(names)
        self.world_poses[object_id] = own.copy()
        self.version += 1

    def remove_world_object(self, object_id: str) -> None:
        """Remove world object ``object_id``.

        Raises:
            MotionError: no such world object (the message lists those there are).
        """
        with self._lock:
            self._refuse_attached(object_id, "remove")
            if object_id not in self.world:
                raise MotionError(
                    f"no collision object {object_id!r} in the planning scene; "
                    f"{did_you_mean(object_id, self.world)}"
                )
            for name in self.world.pop(object_id):
                self.objects.pop(name, None)
            self.world_poses.pop(object_id, None)
            self.urdf_ids.discard(object_id)
            self.version += 1
        self._changed()

    def world_object(self, object_id: str) -> list[CollisionObject]:
        """The primitives of world object ``object_id`` (an empty list when there is none)."""
        with self._lock:
            return [self.objects[n] for n in self.world.get(object_id, ())]

    def world_objects(self) -> dict[str, list[CollisionObject]]:
        """Every world object: id -> its primitives (a snapshot)."""
        with self._lock:
            return {oid: [self.objects[n] for n in names] for oid, names in self.world.items()}

    def reset_world(self) -> int:
        """Remove every world and attached object (the environment stays); returns how many were removed."""
        with self._lock:
            count = len(self.world) + len(self.attached)
            if not count:
                return 0
            for names in self.world.values():
                for name in names:
                    self.objects.pop(name, None)
            self.world.clear()
            self.world_poses.clear()
            self.attached.clear()
            self.urdf_ids.clear()
            self.version += 1
        self._changed()
        return count

    # -- attached objects --------------------------------------------------------------------------

    def attach(
        self,
        object_id: str,
        link: str,
        world_T_link: np.ndarray,
        touch_links: Iterable[str] = (),
    ) -> AttachedObject:
        """Bind world object ``object_id`` to robot link ``link``, where it is now (MoveIt's attach).

        Args:
            object_id: a world object's id.
            link: the robot link it moves with from now on.
            world_T_link: the link's pose now (the object keeps its place relative to the link).
            touch_links: robot links it may touch besides ``link``.

        Raises:
            MotionError: no such world object (naming those there are), it is attached already, or a
                non-finite link pose.
        """
        world_T_link = np.asarray(world_T_link, dtype=float)
        if world_T_link.shape != (4, 4) or not np.all(np.isfinite(world_T_link)):
            raise MotionError(f"the pose of link {link!r} must be a finite 4x4 transform")
        with self._lock:
            if object_id in self.attached:
                raise MotionError(
                    f"collision object {object_id!r} is already attached to {self.attached[object_id].link!r}"
                )
            if object_id not in self.world:
                raise MotionError(
                    f"no collision object {object_id!r} in the planning scene to attach; "
                    f"{did_you_mean(object_id, self.world)}"
                )
            link_T_world = np.linalg.inv(world_T_link)
            names = self.world.pop(object_id)
            primitives = tuple(
                CollisionObject(p.name, p.shape, p.size, link_T_world @ p.world_T_object)
                for p in (self.objects.pop(n) for n in names)
            )
            own = self.world_poses.pop(object_id, np.eye(4))
            attached = AttachedObject(
                object_id,
                link,
                primitives,
                link_T_world @ own,
                frozenset(touch_links) - {link},
                object_id in self.urdf_ids,
            )
            self.attached[object_id] = attached
            self.version += 1
        self._changed()
        return attached

    def detach(self, object_id: str, world_T_link: np.ndarray) -> None:
        """Put attached object ``object_id`` back into the world where it is now (its link at
        ``world_T_link``).

        Raises:
            MotionError: no object of that id is attached (naming those that are), or a bad link pose.
        """
        world_T_link = np.asarray(world_T_link, dtype=float)
        if world_T_link.shape != (4, 4) or not np.all(np.isfinite(world_T_link)):
            raise MotionError("the link's pose must be a finite 4x4 transform")
        with self._lock:
            attached = self.attached.get(object_id)
            if attached is None:
                raise MotionError(
                    f"no collision object {object_id!r} is attached to the robot; "
                    f"{did_you_mean(object_id, self.attached)}"
                )
            placed = [
                CollisionObject(p.name, p.shape, p.size, world_T_link @ p.world_T_object)
                for p in attached.primitives
            ]
            del self.attached[object_id]
            self._store(object_id, placed, world_T_link @ attached.link_T_object)
        self._changed()

    def attached_objects(self) -> dict[str, AttachedObject]:
        """Every attached object, by id (a snapshot)."""
        with self._lock:
            return dict(self.attached)

    def shape_names(self, object_id: str) -> tuple[str, ...]:
        """The names the shapes of object ``object_id`` (in the world or attached) are checked under; ()
        when there is no such object."""
        with self._lock:
            if object_id in self.world:
                return self.world[object_id]
            attached = self.attached.get(object_id)
            return tuple(p.name for p in attached.primitives) if attached is not None else ()

    # -- listeners ---------------------------------------------------------------------------------

    def subscribe(self, listener: Callable[[PlanningScene], None]) -> None:
        """Call ``listener(scene)`` after every change (on the thread that made it; it must not block)."""
        with self._lock:
            self._listeners.append(listener)

    def _changed(self) -> None:
        for listener in list(self._listeners):
            listener(self)

    def add_box(self, name: str, half_extents: Iterable[float], world_T_object: np.ndarray) -> None:
        """Add a box with half extents (x, y, z) in metres at ``world_T_object`` (shape ``(4, 4)``)."""
        self.add(
            CollisionObject(
                name, "box", tuple(float(v) for v in half_extents), np.asarray(world_T_object, float)
            )
        )

    def remove(self, name: str) -> None:
        """Remove object ``name``.

        Raises:
            MotionError: no such object, with the names there are.
        """
        with self._lock:
            if name not in self.objects:
                raise MotionError(
                    f"no collision object {name!r} in the planning scene; {did_you_mean(name, self.objects)}"
                )
            del self.objects[name]
            for object_id, names in list(self.world.items()):
                if name in names:
                    rest = tuple(n for n in names if n != name)
                    if rest:
                        self.world[object_id] = rest
                    else:
                        del self.world[object_id]
                        self.world_poses.pop(object_id, None)
                        self.urdf_ids.discard(object_id)
            self.version += 1
        self._changed()

    @classmethod
    def from_mjcf(
        cls,
        scene_path: str | Path,
        robot_links: Iterable[str],
        *,
        include_free_bodies: bool = False,
        keyframe: str = "default",
        loaded: Any = None,
    ) -> PlanningScene:
        """Collect the static geoms of a MuJoCo scene (everything welded to the world) as collision objects.

        Geoms of bodies named like a robot link are skipped (the robot is checked from its URDF), as are
        visual-only geoms (contype and conaffinity 0). A ground plane becomes a 10 cm thick box under it.

        Args:
            scene_path: the MJCF scene file.
            robot_links: link names of the robot (bodies with these names, and their subtrees, are skipped).
            include_free_bodies: also add free bodies (objects to pick) at their pose in ``keyframe``.
            keyframe: keyframe giving the free bodies' poses (the model's initial pose when absent).
            loaded: the ``mujoco.MjModel`` of ``scene_path`` when the caller loaded it already.

        Raises:
            MotionError: the file cannot be loaded by MuJoCo.
        """
        import mujoco

        from kinema.config.mujoco_scene import load_scene
        from kinema.errors import ConfigError

        try:
            m = loaded if loaded is not None else load_scene(Path(scene_path))
        except ConfigError as exc:
            raise MotionError(str(exc)) from None
        d = mujoco.MjData(m)
        key = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, keyframe)
        if key >= 0:
            mujoco.mj_resetDataKeyframe(m, d, key)
        mujoco.mj_kinematics(m, d)
        links = set(robot_links)
        robot_bodies: set[int] = set()
        for b in range(1, m.nbody):
            parent = int(m.body_parentid[b])
            if m.body(b).name in links or parent in robot_bodies:
                robot_bodies.add(b)
        scene = cls()
        for gi in range(m.ngeom):
            body = int(m.geom_bodyid[gi])
            if body in robot_bodies or (m.geom_contype[gi] == 0 and m.geom_conaffinity[gi] == 0):
                continue
            static = int(m.body_weldid[body]) == 0
            if not static and not include_free_bodies:
                continue
            name = m.geom(gi).name or f"{m.body(body).name or 'world'}_geom{gi}"
            T = np.eye(4)
            T[:3, :3] = d.geom_xmat[gi].reshape(3, 3)
            T[:3, 3] = d.geom_xpos[gi]
            size = m.geom_size[gi]
            gtype = int(m.geom_type[gi])
            if gtype == mujoco.mjtGeom.mjGEOM_PLANE:
                plane = (float(size[0]) if size[0] > 0 else 5.0, float(size[1]) if size[1] > 0 else 5.0, 0.05)
                T[:3, 3] = T[:3, 3] - T[:3, 2] * 0.05
                scene.add(CollisionObject(name, "box", plane, T))
            elif gtype == mujoco.mjtGeom.mjGEOM_BOX:
                scene.add(CollisionObject(name, "box", tuple(float(s) for s in size[:3]), T))
            elif gtype == mujoco.mjtGeom.mjGEOM_CYLINDER:
                scene.add(CollisionObject(name, "cylinder", (float(size[0]), float(size[1])), T))
            elif gtype == mujoco.mjtGeom.mjGEOM_CAPSULE:
                scene.add(CollisionObject(name, "capsule", (float(size[0]), float(size[1])), T))
            elif gtype == mujoco.mjtGeom.mjGEOM_SPHERE:
                scene.add(CollisionObject(name, "sphere", (float(size[0]),), T))
            else:
                # Meshes, ellipsoids, height fields: approximate by the geom's bounding box.
                half = tuple(float(v) for v in m.geom_aabb[gi][3:])
                T[:3, 3] = T[:3, 3] + T[:3, :3] @ m.geom_aabb[gi][:3]
                scene.add(CollisionObject(name, "box", half, T))
        return scene
