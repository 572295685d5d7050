"""The agent's planning scene as MoveIt's move_group offers it: ``/get_planning_scene`` and
``/monitored_planning_scene``.

One :class:`kinema.motion.PlanningScene` per behavior context (the runtime has one): the static geometry
of the config's MuJoCo scene plus the collision objects objectives add. The core behaviors plan against
it (:func:`scene_of`); every change is published, latched, on ``/monitored_planning_scene``; and
``/get_planning_scene`` (``moveit_msgs/srv/GetPlanningScene``) answers with it, honouring the request's
``components`` as move_group does: scene settings (name, robot model), the robot state (the latest
``/joint_states``), the world objects' names, or their names and geometry. The cell's own geometry is
part of every plan but not listed, as MoveIt lists only objects added to the world.

The messages are made by :mod:`kinema.motion.planning_scene_messages`.
"""

from __future__ import annotations

import threading
import weakref
from typing import TYPE_CHECKING, Any

from kinema.motion.planning_scene_messages import (
    PLANNING_SCENE_TYPE,
    planning_scene_dict,
    planning_scene_message,
)
from kinema.viz.topics import PLANNING_SCENE_TOPIC

if TYPE_CHECKING:
    from kinema.motion import PlanningScene, RobotModel

GET_PLANNING_SCENE = "/get_planning_scene"
GET_PLANNING_SCENE_TYPE = "moveit_msgs/srv/GetPlanningScene"
JOINT_STATES = "/joint_states"
JOINT_STATES_TYPE = "sensor_msgs/msg/JointState"

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
        return {"scene": planning_scene_dict(scene, name, latest[0], int(request.components.components))}

    node.create_subscription(JOINT_STATES_TYPE, JOINT_STATES, on_joint_states)
    node.create_service(GET_PLANNING_SCENE_TYPE, GET_PLANNING_SCENE, on_request)
