"""The agent's planning scene as MoveIt's move_group offers it: ``/get_planning_scene`` and
``/monitored_planning_scene``.

One :class:`kinema.motion.PlanningScene` per behavior context (the runtime has one): the static geometry
of the config's MuJoCo scene plus the collision objects objectives add. The core behaviors plan against
it (:func:`scene_of`); every change is published, latched, on ``/monitored_planning_scene``; and
``/get_planning_scene`` (``moveit_msgs/srv/GetPlanningScene``) answers with it, honouring the request's
``components`` as move_group does: scene settings (name, robot model), the robot state (the latest
``/joint_states``), the world objects' names, or their names and geometry. The cell's own geometry is
part of every plan but not listed, as MoveIt lists only objects added to the world.

World objects become ``CollisionObject`` messages in ``world``: identity object pose, each primitive
placed in the world.
"""

from __future__ import annotations

import threading
import weakref
from typing import TYPE_CHECKING, Any

import numpy as np

from kinema.transforms import pose_dict
from kinema.viz.topics import PLANNING_SCENE_TOPIC, PLANNING_SCENE_TYPE

if TYPE_CHECKING:
    from kinema.motion import CollisionObject, PlanningScene, RobotModel

GET_PLANNING_SCENE = "/get_planning_scene"
GET_PLANNING_SCENE_TYPE = "moveit_msgs/srv/GetPlanningScene"
JOINT_STATES = "/joint_states"
JOINT_STATES_TYPE = "sensor_msgs/msg/JointState"

# moveit_msgs/PlanningSceneComponents bits this service honours.
SCENE_SETTINGS, ROBOT_STATE, WORLD_OBJECT_NAMES, WORLD_OBJECT_GEOMETRY = 1, 2, 8, 16
EVERYTHING = SCENE_SETTINGS | ROBOT_STATE | WORLD_OBJECT_NAMES | WORLD_OBJECT_GEOMETRY
BOX, SPHERE, CYLINDER = 1, 2, 3
ADD = 0

_SCENES: weakref.WeakKeyDictionary[Any, PlanningScene] = weakref.WeakKeyDictionary()
_SCENES_LOCK = threading.Lock()


def scene_of(context: Any, model: RobotModel) -> PlanningScene:
    """The planning scene of ``context``, made on first use from its config's MuJoCo scene.

    With a transport node, every change of the scene is published (latched) on
    ``/monitored_planning_scene``.
    """
    from kinema.motion import PlanningScene

    with _SCENES_LOCK:
        scene = _SCENES.get(context)
        if scene is None:
            config = getattr(context, "config", None)
            path = getattr(config, "mujoco_model_path", None) if config is not None else None
            scene = PlanningScene.from_mjcf(path, model.link_names) if path is not None else PlanningScene()
            _SCENES[context] = scene
            if getattr(context, "node", None) is not None:
                _publish_changes(context, scene, str(getattr(model, "name", "")))
        return scene


def existing_scene(context: Any) -> PlanningScene | None:
    """The planning scene of ``context`` if one was made or set, else None (nothing is loaded)."""
    with _SCENES_LOCK:
        return _SCENES.get(context)


def set_scene(context: Any, scene: PlanningScene) -> None:
    """Plan against (and serve) ``scene`` in ``context`` from now on."""
    with _SCENES_LOCK:
        _SCENES[context] = scene


def _publish_changes(context: Any, scene: PlanningScene, robot_model_name: str) -> None:
    publisher = context.publisher(context.node, PLANNING_SCENE_TYPE, PLANNING_SCENE_TOPIC, latched=True)

    def publish(changed: PlanningScene) -> None:
        publisher.publish(planning_scene_message(changed, robot_model_name))

    scene.subscribe(publish)
    publish(scene)


def serve_planning_scene(node: Any, context: Any) -> None:
    """Serve ``/get_planning_scene`` on ``node`` from the planning scene of ``context``.

    The scene is made at the first request if no behavior has used it yet; without a robot model the
    answer is an empty scene.
    """
    latest: list[Any] = [None]

    def on_joint_states(message: Any) -> None:
        latest[0] = message

    def on_request(request: Any) -> Any:
        from kinema.motion import PlanningScene

        model = context.robot_model
        scene = scene_of(context, model) if model is not None else PlanningScene()
        name = str(getattr(model, "name", "")) if model is not None else ""
        components = int(request.components.components) or EVERYTHING
        return {"scene": planning_scene_dict(scene, name, latest[0], components)}

    node.create_subscription(JOINT_STATES_TYPE, JOINT_STATES, on_joint_states)
    node.create_service(GET_PLANNING_SCENE_TYPE, GET_PLANNING_SCENE, on_request)


def _primitive_dict(obj: CollisionObject) -> dict[str, Any]:
    if obj.shape == "box":
        return {"type": BOX, "dimensions": [2 * float(v) for v in obj.size]}
    if obj.shape == "sphere":
        return {"type": SPHERE, "dimensions": [float(obj.size[0])]}
    # cylinders, and capsules drawn as the cylinder around them
    extra = float(obj.size[0]) if obj.shape == "capsule" else 0.0
    return {"type": CYLINDER, "dimensions": [2 * float(obj.size[1]) + 2 * extra, float(obj.size[0])]}


def collision_object_dict(object_id: str, primitives: list[CollisionObject]) -> dict[str, Any]:
    """A ``moveit_msgs/CollisionObject`` dict of a world object, in ``world``."""
    return {
        "header": {"frame_id": "world"},
        "pose": {"orientation": {"w": 1.0}},
        "id": object_id,
        "primitives": [_primitive_dict(p) for p in primitives],
        "primitive_poses": [pose_dict(np.asarray(p.world_T_object, float)) for p in primitives],
        "operation": ADD,
    }


def planning_scene_message(
    scene: PlanningScene, robot_model_name: str = "", joint_state: Any = None, components: int = EVERYTHING
) -> Any:
    """A full ``moveit_msgs/PlanningScene`` (``is_diff`` false) of ``scene``'s world objects (see
    :func:`planning_scene_dict`)."""
    from kinema.transport import from_dict

    return from_dict(
        PLANNING_SCENE_TYPE, planning_scene_dict(scene, robot_model_name, joint_state, components)
    )


def planning_scene_dict(
    scene: PlanningScene, robot_model_name: str = "", joint_state: Any = None, components: int = EVERYTHING
) -> dict[str, Any]:
    """A ``moveit_msgs/PlanningScene`` as a dict.

    ``components`` (``moveit_msgs/PlanningSceneComponents`` bits) selects the parts, as move_group's
    ``/get_planning_scene`` does: names only without ``WORLD_OBJECT_GEOMETRY``, no robot state without
    ``ROBOT_STATE``.
    """
    data: dict[str, Any] = {"is_diff": False}
    if components & SCENE_SETTINGS:
        data["name"] = "kinema"
        data["robot_model_name"] = robot_model_name
    objects = sorted(scene.world_objects().items())
    if components & WORLD_OBJECT_GEOMETRY:
        data["world"] = {"collision_objects": [collision_object_dict(oid, prims) for oid, prims in objects]}
    elif components & WORLD_OBJECT_NAMES:
        data["world"] = {
            "collision_objects": [
                {"header": {"frame_id": "world"}, "id": oid, "operation": ADD} for oid, _ in objects
            ]
        }
    if joint_state is not None and components & ROBOT_STATE:
        data["robot_state"] = {
            "joint_state": {
                "name": [str(n) for n in joint_state.name],
                "position": [float(p) for p in joint_state.position],
            }
        }
    return data
