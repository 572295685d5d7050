"""The viewer's copy of the MuJoCo scene: its geoms as meshcat objects and its bodies' poses from a qpos.

The driver publishes MuJoCo's whole ``qpos`` (``/mujoco/scene_state``) and the joint positions
(``/joint_states``); running ``mj_kinematics`` on a local ``MjData`` with them gives every body's pose
exactly as the simulation has it, free objects included. meshcat gets one node per body
(``/kinema/bodies/<body>``) holding its geoms, so a frame moves only the bodies whose pose changed;
bodies welded to the world are placed once.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import kinema.mujoco_gl  # noqa: F401  (MuJoCo's OpenGL backend is chosen before the lazy mujoco imports below)
from kinema.errors import ConfigError
from kinema.viz import scene_commands as sc
from kinema.viz.geom_shapes import GeomVisual, geom_visuals, safe_name
from kinema.viz.meshcat_server import Command

log = logging.getLogger("kinema.viz")

ROOT = "/kinema"
BODIES = f"{ROOT}/bodies"
# A body is re-sent when it moved more than this (m, or the same in rotation-matrix entries).
MOVE_EPSILON = 1e-5
BACKGROUND_TOP = [0.75, 0.8, 0.85]
BACKGROUND_BOTTOM = [0.35, 0.4, 0.45]
# mjtJoint: free, ball, slide, hinge.
_FREE, _BALL, _SLIDE, _HINGE = range(4)


@dataclass(frozen=True)
class BodyNode:
    """A body that carries visible geoms: its meshcat path and whether it can move at all."""

    body_id: int
    name: str
    path: str
    static: bool


#: A fixed geom this small (bounding sphere radius, m) is something the robot works on, and is framed.
WORKSPACE_ITEM_RADIUS = 0.5


class SceneModel:
    """A MuJoCo model prepared for meshcat (see the module docstring).

    Args:
        model: the compiled ``mujoco.MjModel``.
        end_effector: the body whose path planned trajectories are drawn for (None: guessed per trajectory).
        keyframe: the keyframe to show before the first state arrives.
    """

    def __init__(self, model: Any, end_effector: str | None = None, keyframe: str | None = None) -> None:
        import mujoco

        self.model = model
        self.data = mujoco.MjData(model)
        self._path_data = mujoco.MjData(model)
        if keyframe:
            key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, keyframe)
            if key >= 0:
                mujoco.mj_resetDataKeyframe(model, self.data, key)
        self.visuals: list[GeomVisual] = geom_visuals(model)
        self.bodies = self._body_nodes()
        self.joint_qpos = {
            model.joint(j).name: int(model.jnt_qposadr[j])
            for j in range(model.njnt)
            if int(model.jnt_type[j]) in (_SLIDE, _HINGE)
        }
        self.end_effector = self._body_id(end_effector) if end_effector else None
        self._sent: dict[int, np.ndarray] = {}
        mujoco.mj_kinematics(model, self.data)

    @classmethod
    def from_file(
        cls, path: Path, end_effector: str | None = None, keyframe: str | None = None
    ) -> SceneModel:
        """Load an MJCF scene.

        Raises:
            ConfigError: the file is missing or MuJoCo cannot load it.
        """
        from kinema.config.mujoco_scene import load_scene

        if not path.is_file():
            raise ConfigError(f"MuJoCo scene {path} does not exist")
        return cls(load_scene(path), end_effector, keyframe)

    # -- building the scene ---------------------------------------------------------------------------

    def _body_nodes(self) -> list[BodyNode]:
        model = self.model
        names: set[str] = set()
        nodes = []
        for body_id in sorted({v.body_id for v in self.visuals}):
            name = safe_name(model.body(body_id).name, f"body{body_id}")
            if name in names:
                name = f"{name}_{body_id}"
            names.add(name)
            # Welded to the world and not a mocap body: its pose never changes.
            static = int(model.body_weldid[body_id]) == 0 and int(model.body_mocapid[body_id]) < 0
            nodes.append(BodyNode(body_id, name, f"{BODIES}/{name}", static))
        return nodes

    def _body_id(self, name: str) -> int | None:
        import mujoco

        body = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name)
        if body < 0:
            log.warning("end effector %r is not a body of the MuJoCo scene; guessing it per trajectory", name)
            return None
        return int(body)

    def scene_commands(self) -> list[Command]:
        """Everything to draw the scene from scratch: background, geoms, and every body at its pose."""
        commands = [
            sc.delete(ROOT),
            # The floor is part of the model; meshcat's own grid and axes would fight with it.
            sc.set_property("/Grid", "visible", False),
            sc.set_property("/Axes", "visible", False),
            sc.set_property("/Background", "top_color", BACKGROUND_TOP),
            sc.set_property("/Background", "bottom_color", BACKGROUND_BOTTOM),
        ]
        path_of = {node.body_id: node.path for node in self.bodies}
        for visual in self.visuals:
            geom_path = f"{path_of[visual.body_id]}/{visual.name}"
            material = visual.material()
            commands.append(sc.set_transform(geom_path, visual.transform))
            for part in visual.parts:
                import meshcat.geometry as g

                part_path = f"{geom_path}/{part.name}"
                commands.append(sc.set_object(part_path, g.Mesh(part.geometry, material)))
                if not np.allclose(part.transform, np.eye(4)):
                    commands.append(sc.set_transform(part_path, part.transform))
        self._sent.clear()
        commands += self.body_commands(force=True)
        return commands

    # -- state ---------------------------------------------------------------------------------------

    def set_qpos(self, qpos: Sequence[float]) -> bool:
        """Take the simulation's whole qpos; False (nothing changed) when its size is not this model's."""
        if len(qpos) != self.model.nq:
            return False
        self.data.qpos[:] = qpos
        return True

    def set_joint_positions(self, names: Sequence[str], positions: Sequence[float]) -> int:
        """Set hinge and slide joints by name (unknown names are skipped); returns how many were set."""
        count = 0
        for name, value in zip(names, positions, strict=False):
            address = self.joint_qpos.get(str(name))
            if address is not None:
                self.data.qpos[address] = float(value)
                count += 1
        return count

    def body_commands(self, force: bool = False) -> list[Command]:
        """Run the kinematics and return ``set_transform`` for every body that moved (all with ``force``)."""
        import mujoco

        mujoco.mj_kinematics(self.model, self.data)
        commands = []
        for node in self.bodies:
            if node.static and not force and node.body_id in self._sent:
                continue
            pose = self.body_pose(node.body_id)
            last = self._sent.get(node.body_id)
            if force or last is None or np.abs(pose - last).max() > MOVE_EPSILON:
                self._sent[node.body_id] = pose
                commands.append(sc.set_transform(node.path, pose))
        return commands

    def body_pose(self, body_id: int) -> np.ndarray:
        """Body ``body_id``'s world pose (4x4) as of the last :meth:`body_commands`."""
        pose = np.eye(4)
        pose[:3, :3] = self.data.xmat[body_id].reshape(3, 3)
        pose[:3, 3] = self.data.xpos[body_id]
        return pose

    def frame_pose(self, frame_id: str) -> np.ndarray | None:
        """World pose of a frame named like a body ("world", "" and "map" are the world); None if unknown."""
        import mujoco

        if frame_id in ("", "world", "map", "odom"):
            return np.eye(4)
        body = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, frame_id)
        if body < 0:
            return None
        return self.body_pose(int(body))

    # -- planned paths -------------------------------------------------------------------------------

    def tool_path(self, joint_names: Sequence[str], positions: Sequence[Sequence[float]]) -> np.ndarray:
        """World positions (N, 3) of the end effector along a joint trajectory, from the current state."""
        import mujoco

        names = [str(n) for n in joint_names]
        body = self.end_effector if self.end_effector is not None else self._guess_tool(names)
        data = self._path_data
        data.qpos[:] = self.data.qpos
        addresses = [self.joint_qpos.get(n) for n in names]
        points = np.zeros((len(positions), 3))
        for row, values in enumerate(positions):
            for address, value in zip(addresses, values, strict=False):
                if address is not None:
                    data.qpos[address] = float(value)
            mujoco.mj_kinematics(self.model, data)
            points[row] = data.xpos[body]
        return points

    def _guess_tool(self, joint_names: list[str]) -> int:
        """The deepest body below the last of these joints (the tool of a serial arm)."""
        import mujoco

        bodies = [
            int(self.model.jnt_bodyid[j])
            for name in joint_names
            if (j := mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, name)) >= 0
        ]
        if not bodies:
            return 0
        body = max(bodies, key=self._depth)
        while True:
            children = [
                b for b in range(self.model.nbody) if int(self.model.body_parentid[b]) == body and b != body
            ]
            if not children:
                return body
            body = children[0]

    def _depth(self, body: int) -> int:
        depth = 0
        while body != 0:
            body = int(self.model.body_parentid[body])
            depth += 1
        return depth

    # -- camera --------------------------------------------------------------------------------------

    def camera_view(self) -> dict[str, Any]:
        """Where the page puts its camera: looking from the front at the robot and its workspace, whole.

        The direction is the model's first world-fixed camera's (on the world body or a body welded to it,
        such as lab_sim's scene camera, whose pose no joint changes), else MuJoCo's free camera's (the
        scene's ``<visual><global azimuth elevation>``). The camera looks at the centre of what the scene
        draws at its start pose (floors left out) from the distance that fits all of it in the field of
        view, so every page load starts on the same, whole picture of the cell.
        """
        import mujoco

        model = self.model
        fov = float(model.vis.global_.fovy)
        forward: np.ndarray | None = None
        for cam in range(model.ncam):
            if int(model.body_weldid[int(model.cam_bodyid[cam])]) != 0:
                continue
            posed = mujoco.MjData(model)
            mujoco.mj_kinematics(model, posed)
            mujoco.mj_camlight(model, posed)
            rotation = np.asarray(posed.cam_xmat[cam], dtype=float).reshape(3, 3)
            forward = -rotation[:, 2]  # MuJoCo cameras look along their -z axis
            fov = float(model.cam_fovy[cam])
            break
        if forward is None:
            azimuth = np.radians(float(model.vis.global_.azimuth))
            elevation = np.radians(float(model.vis.global_.elevation))
            forward = np.array(
                [np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation)]
            )
        forward = forward / np.linalg.norm(forward)
        center, radius = self._drawn_bounds()
        # The sphere around what is drawn fits the (vertical) field of view, with a little margin.
        distance = max(1.08 * radius / np.sin(np.radians(fov) / 2), 0.5)
        return {
            "camera": {
                "position": (center - forward * distance).tolist(),
                "target": center.tolist(),
                "fov": fov,
            }
        }

    def _drawn_bounds(self) -> tuple[np.ndarray, float]:
        """Centre and radius (m) of the box around the robot and what it works on at the start pose.

        That is every drawn geom of a body that moves (the arm, the rail's carriage, free objects) and the
        small fixed ones beside them (a tray, bottles: within :data:`WORKSPACE_ITEM_RADIUS`), each by its
        own box turned into the world; large fixed scenery (a 3 m rail pedestal, the table, a floor) would
        make the robot small. A scene where nothing moves is framed whole (planes aside).
        """
        model, data = self.model, self.data
        drawn = [v.geom_id for v in self.visuals if v.kind not in ("plane", "hfield")]
        moving = [g for g in drawn if int(model.body_weldid[int(model.geom_bodyid[g])]) != 0]
        if not moving:
            return self._box_of(drawn) if drawn else (np.asarray(model.stat.center, dtype=float), 1.0)
        # Small fixed things beside what moves (a tray, bottles) belong to the workspace; a camera stand
        # or a shelf across the room does not.
        center, radius = self._box_of(moving)
        near = [
            g
            for g in drawn
            if g not in moving
            and float(model.geom_rbound[g]) <= WORKSPACE_ITEM_RADIUS
            and np.linalg.norm((np.asarray(data.geom_xpos[g]) - center)[:2]) <= radius
        ]
        return self._box_of(moving + near)

    def _box_of(self, geoms: list[int]) -> tuple[np.ndarray, float]:
        """Centre and half diagonal (m) of the world box around ``geoms`` (each by its own turned box)."""
        model, data = self.model, self.data
        signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
        corners = []
        for geom in geoms:
            box = np.asarray(model.geom_aabb[geom], dtype=float)  # centre, half sizes in the geom frame
            local = box[:3] + signs * box[3:]
            rotation = np.asarray(data.geom_xmat[geom], dtype=float).reshape(3, 3)
            corners.append(np.asarray(data.geom_xpos[geom], dtype=float) + local @ rotation.T)
        points = np.concatenate(corners)
        low, high = points.min(axis=0), points.max(axis=0)
        return (low + high) / 2, float(np.linalg.norm(high - low) / 2)
