"""The planning scene: collision objects in the world the robot must not touch (table, tray, walls, ...)."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

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


@dataclass
class PlanningScene:
    """The obstacles planning checks against, by name. ``version`` changes whenever the scene does."""

    objects: dict[str, CollisionObject] = field(default_factory=dict)
    version: int = 0

    def add(self, obj: CollisionObject) -> None:
        """Add or replace an object.

        Raises:
            MotionError: unknown shape or wrong number of size values.
        """
        expected = {"box": 3, "cylinder": 2, "capsule": 2, "sphere": 1}
        if obj.shape not in expected:
            raise MotionError(
                f"unknown collision shape {obj.shape!r} for {obj.name!r}; {did_you_mean(obj.shape, SHAPES)}"
            )
        if len(obj.size) != expected[obj.shape]:
            raise MotionError(
                f"a {obj.shape} needs {expected[obj.shape]} size values, {obj.name!r} has {len(obj.size)}"
            )
        self.objects[obj.name] = obj
        self.version += 1

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
        if name not in self.objects:
            raise MotionError(
                f"no collision object {name!r} in the planning scene; {did_you_mean(name, self.objects)}"
            )
        del self.objects[name]
        self.version += 1

    @classmethod
    def from_mjcf(
        cls,
        scene_path: str | Path,
        robot_links: Iterable[str],
        *,
        include_free_bodies: bool = False,
        keyframe: str = "default",
    ) -> PlanningScene:
        """Collect the static geoms of a MuJoCo scene (everything welded to the world) as collision objects.

        Geoms of bodies named like a robot link are skipped (the robot is checked from its URDF), as are
        visual-only geoms (contype and conaffinity 0). A ground plane becomes a 10 cm thick box under it.

        Args:
            scene_path: the MJCF scene file.
            robot_links: link names of the robot (bodies with these names, and their subtrees, are skipped).
            include_free_bodies: also add free bodies (objects to pick) at their pose in ``keyframe``.
            keyframe: keyframe giving the free bodies' poses (the model's initial pose when absent).

        Raises:
            MotionError: the file cannot be loaded by MuJoCo.
        """
        import mujoco

        try:
            m = mujoco.MjModel.from_xml_path(str(scene_path))
        except ValueError as exc:
            raise MotionError(f"MuJoCo cannot load scene {scene_path}: {exc}") from exc
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
