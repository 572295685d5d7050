"""The frame tree a behavior sees now: robot links at the current joint state, simulated objects, cameras
and planning-scene objects (:class:`kinema.motion.FrameTree` filled from the running cell).

- robot links: the latest ``/joint_states`` through the robot model (``world``, ``base_link``, ``tool0``,
  ``grasp_link``, ...);
- simulated objects: the MuJoCo driver's free bodies (``/mujoco/bodies``), when a simulator runs;
- cameras: the cameras of the config's MuJoCo scene that are fixed in the world (``scene_camera``), in
  MuJoCo's camera convention (looking along -z, y up);
- planning-scene objects: each world object's first primitive, under the object's id.
"""

from __future__ import annotations

import threading
import weakref
from typing import Any

import numpy as np

import kinema.mujoco_gl  # noqa: F401  (MuJoCo's OpenGL backend is chosen before the lazy mujoco import below)
from kinema.errors import KinemaError, ObjectiveError
from kinema.transforms import pose_from_message

from ..motion.joint_states import joint_state_monitor
from ..motion.planning_resources import planning_scene, robot_model

BODIES_SERVICE = "/mujoco/bodies"
BODIES_TYPE = "kinema_msgs/srv/GetSimBodies"
# A simulator answers within milliseconds; a real robot has none, and the tree must not wait for it.
BODIES_TIMEOUT = 1.0

_CAMERAS: weakref.WeakKeyDictionary[Any, dict[str, np.ndarray]] = weakref.WeakKeyDictionary()
_LOCK = threading.Lock()


def _camera_frames(context: Any) -> dict[str, np.ndarray]:
    """World-fixed cameras of the config's MuJoCo scene (cached per context)."""
    with _LOCK:
        cached = _CAMERAS.get(context)
        if cached is not None:
            return cached
    frames: dict[str, np.ndarray] = {}
    config = getattr(context, "config", None)
    path = getattr(config, "mujoco_model_path", None) if config is not None else None
    if path is not None:
        import mujoco

        try:
            model = mujoco.MjModel.from_xml_path(str(path))
        except ValueError:
            model = None
        if model is not None:
            data = mujoco.MjData(model)
            mujoco.mj_forward(model, data)  # camera poses come from mj_camlight, which this runs
            for index in range(model.ncam):
                name = model.camera(index).name
                if name and int(model.body_weldid[model.cam_bodyid[index]]) == 0:
                    matrix = np.eye(4)
                    matrix[:3, :3] = data.cam_xmat[index].reshape(3, 3)
                    matrix[:3, 3] = data.cam_xpos[index]
                    frames[name] = matrix
    with _LOCK:
        _CAMERAS[context] = frames
    return frames


def _sim_bodies(behavior: Any) -> dict[str, np.ndarray]:
    node = behavior.context.node
    if node is None:
        return {}
    try:
        client = behavior.context.service_client(node, BODIES_TYPE, BODIES_SERVICE)
        if not client.service_is_ready():
            return {}  # no simulator on the graph (a real robot): objects come from perception instead
        response = client.call({}, timeout=BODIES_TIMEOUT)
    except KinemaError:
        return {}  # no simulator (a real robot): objects come from perception instead
    return {str(body.name): pose_from_message(body.pose) for body in response.bodies}


def current_frame_tree(behavior: Any, joint_state: Any = None, at: float = 0.0) -> Any:
    """The frame tree of ``behavior``'s cell now (or with the robot at ``joint_state``, or as it was at
    stamp ``at``).

    Args:
        behavior: the calling behavior (its context gives the model, transport and scene).
        joint_state: a ``sensor_msgs/JointState`` to place the robot at instead of the current state;
            joints it does not name keep their current value (or 0 without a robot driver).
        at: a stamp (s, the robot's clock) to place the robot at, e.g. a camera frame's: the robot's
            joints as they were then (:meth:`JointStateMonitor.positions_at`); 0: now.

    Raises:
        ObjectiveError: no robot model, or no joint state to place the robot.
    """
    from kinema.motion import FrameTree

    name = getattr(behavior, "registration_id", type(behavior).__name__)
    model = robot_model(behavior.context, name)
    if joint_state is None:
        q = joint_state_monitor(behavior.context, name).positions_at(model.joint_names, at)
    else:
        q = _positions_from(behavior, model, joint_state)
    fixed: dict[str, np.ndarray] = dict(_camera_frames(behavior.context))
    fixed.update(_sim_bodies(behavior))
    for object_id, primitives in planning_scene(behavior.context, model).world_objects().items():
        if primitives:
            fixed[object_id] = primitives[0].world_T_object
    return FrameTree(model, q, fixed)


def _positions_from(behavior: Any, model: Any, joint_state: Any) -> np.ndarray:
    names = [str(n) for n in getattr(joint_state, "name", [])]
    values = [float(v) for v in getattr(joint_state, "position", [])]
    if len(names) != len(values):
        raise ObjectiveError(f"the joint state names {len(names)} joints but gives {len(values)} positions")
    unknown = [n for n in names if n not in model.joint_names]
    known = set(model.joint_names)
    if unknown and not any(n in known for n in names):
        raise ObjectiveError(
            f"the joint state names none of the robot's joints ({', '.join(unknown[:4])}); "
            f"valid: {', '.join(model.joint_names)}"
        )
    node = behavior.context.node
    if node is not None:
        try:
            q = joint_state_monitor(behavior.context, behavior.registration_id).positions(
                model.joint_names, timeout=0.5
            )
        except KinemaError:
            q = np.zeros(len(model.joint_names))
    else:
        q = np.zeros(len(model.joint_names))
    index = {n: i for i, n in enumerate(model.joint_names)}
    for joint, value in zip(names, values, strict=True):
        if joint in index:
            q[index[joint]] = value
    return q
