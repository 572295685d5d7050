"""The frame tree of a running cell: what :class:`~kinema.motion.FrameTree` is filled with for behaviors.

- robot links: the robot model at a configuration the caller gives (the latest ``/joint_states``, or a
  state at a camera frame's stamp);
- cameras: the cameras of the config's MuJoCo scene that are fixed in the world (``scene_camera``), in
  MuJoCo's camera convention (looking along -z, y up), read once per cell;
- simulated objects: the MuJoCo driver's free bodies (``/mujoco/bodies``), when a simulator runs;
- planning-scene objects: each world object's first primitive, under the object's id; an object attached
  to the robot at its own pose on its link, at the configuration;
- published frames: frames a behavior broadcasts while it runs (``PublishTF``), each a pose in a parent
  frame of the tree (a robot link, the world, another frame), so later behaviors can name them. When the
  behavior stops, the frame stays known for :data:`TF_LINGER` seconds, as a TF listener's buffer keeps
  the last transform it heard (tf2's default cache is 10 s).

One :class:`CellFrames` belongs to a :class:`~kinema.behaviors.BehaviorContext` (``context.frames``).
"""

from __future__ import annotations

import pathlib
import threading
import time
from typing import TYPE_CHECKING, Any

import numpy as np

from kinema.drivers.mujoco.names import BODIES_SERVICE, BODIES_TYPE
from kinema.errors import KinemaError
from kinema.transforms import pose_from_message

if TYPE_CHECKING:
    from kinema.behaviors.context import BehaviorContext
    from kinema.motion.frames import FrameTree

__all__ = ["BODIES_TIMEOUT", "TF_LINGER", "CellFrames", "fixed_camera_frames"]

# A simulator answers within milliseconds; a real robot has none, and the tree must not wait for it.
BODIES_TIMEOUT = 1.0
# Seconds a published frame stays known after its publisher stops (tf2's default buffer length).
TF_LINGER = 10.0


def fixed_camera_frames(mjcf_path: Any) -> dict[str, np.ndarray]:
    """``world_T_camera`` of each named camera of a MuJoCo scene that is fixed in the world (an unreadable
    scene has none)."""
    import mujoco

    import kinema.mujoco_gl  # noqa: F401  (MuJoCo's OpenGL backend is chosen before mujoco loads)
    from kinema.config.mujoco_scene import load_scene
    from kinema.errors import ConfigError

    try:
        model = load_scene(pathlib.Path(mjcf_path))
    except ConfigError:
        return {}
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)  # camera poses come from mj_camlight, which this runs
    frames: dict[str, np.ndarray] = {}
    for index in range(model.ncam):
        name = model.camera(index).name
        if name and int(model.body_weldid[model.cam_bodyid[index]]) == 0:
            matrix = np.eye(4)
            matrix[:3, :3] = data.cam_xmat[index].reshape(3, 3)
            matrix[:3, 3] = data.cam_xpos[index]
            frames[name] = matrix
    return frames


class CellFrames:
    """The named frames of one cell, for :class:`~kinema.motion.FrameTree` s at a robot configuration.

    Args:
        context: the behavior context of the cell (its config, transport node, robot model and
            planning scene).
    """

    def __init__(self, context: BehaviorContext) -> None:
        self._context = context
        self._cameras: dict[str, np.ndarray] | None = None
        self._lock = threading.Lock()
        # child -> (parent, parent_T_child, monotonic time it is forgotten at; inf while published)
        self._published: dict[str, tuple[str, np.ndarray, float]] = {}

    def publish(self, child: str, parent: str, parent_T_child: np.ndarray) -> None:
        """Make frame ``child`` known at ``parent_T_child`` in frame ``parent`` until :meth:`release`.

        A frame published again moves. ``parent`` is resolved whenever a tree is made, so a frame published
        in a robot link's frame moves with the robot.
        """
        with self._lock:
            self._published[child] = (parent, np.array(parent_T_child, dtype=float), float("inf"))

    def release(self, child: str, linger: float = TF_LINGER) -> None:
        """Stop publishing ``child``: it stays known for ``linger`` seconds (0: forgotten at once)."""
        with self._lock:
            entry = self._published.get(child)
            if entry is not None:
                self._published[child] = (entry[0], entry[1], time.monotonic() + max(0.0, linger))

    def published(self) -> dict[str, tuple[str, np.ndarray]]:
        """The frames published (or released less than their linger ago): child -> (parent,
        ``parent_T_child``), a snapshot."""
        now = time.monotonic()
        with self._lock:
            for child in [c for c, (_, _, until) in self._published.items() if until <= now]:
                del self._published[child]
            return {child: (parent, pose) for child, (parent, pose, _) in self._published.items()}

    @property
    def cameras(self) -> dict[str, np.ndarray]:
        """``world_T_camera`` of the world-fixed cameras of the config's MuJoCo scene (read on first use)."""
        with self._lock:
            if self._cameras is None:
                config = self._context.config
                path = config.mujoco_model_path if config is not None else None
                self._cameras = fixed_camera_frames(path) if path is not None else {}
            return self._cameras

    def sim_bodies(self) -> dict[str, np.ndarray]:
        """``world_T_body`` of the simulator's free bodies; none without a simulator on the network."""
        node = self._context.node
        if node is None:
            return {}
        try:
            client = self._context.service_client(node, BODIES_TYPE, BODIES_SERVICE)
            if not client.service_is_ready():
                return {}  # no simulator on the graph (a real robot): objects come from perception instead
            response = client.call({}, timeout=BODIES_TIMEOUT)
        except KinemaError:
            return {}  # no simulator (a real robot): objects come from perception instead
        return {str(body.name): pose_from_message(body.pose) for body in response.bodies}

    def fixed(self) -> dict[str, np.ndarray]:
        """Every frame that is not a robot link: cameras, then simulated and planning-scene objects."""
        frames: dict[str, np.ndarray] = dict(self.cameras)
        frames.update(self.sim_bodies())
        scene = self._context.planning_scene
        for object_id, primitives in scene.world_objects().items():
            if primitives:
                frames[object_id] = primitives[0].world_T_object
        return frames

    def tree(self, q: np.ndarray) -> FrameTree:
        """The frame tree with the robot at configuration ``q`` (over the robot model's joint names)."""
        from kinema.motion.frames import FrameTree

        model = self._context.robot_model
        fixed = self.fixed()
        base = FrameTree(model, q, fixed)
        attached = self._context.planning_scene.attached_objects()
        published = self.published()
        if not attached and not published:
            return base
        extra: dict[str, np.ndarray] = {}
        for object_id, item in attached.items():
            if item.link in base:
                extra[object_id] = base.world_T(item.link) @ item.link_T_object
        # A published frame may hang from another published frame: resolve in passes.
        pending = dict(published)
        while pending:
            resolved = False
            for child, (parent, parent_T_child) in list(pending.items()):
                if parent in base or parent in extra:
                    world_T_parent = extra[parent] if parent in extra else base.world_T(parent)
                    extra[child] = world_T_parent @ parent_T_child
                    del pending[child]
                    resolved = True
            if not resolved:
                break  # frames whose parent nobody knows (any more) stay unknown
        if not extra:
            return base
        return FrameTree(model, q, {**fixed, **extra})
