"""The agent's planning scene as MoveIt's move_group offers it: ``/get_planning_scene`` and
``/monitored_planning_scene``.

The scene is the behavior context's (``BehaviorContext.planning_scene``; the runtime has one context): the
static geometry of the config's MuJoCo scene plus the collision objects objectives add. The core behaviors
plan against it; every change is published, latched, on ``/monitored_planning_scene``; and
``/get_planning_scene`` (``moveit_msgs/srv/GetPlanningScene``) answers with it, honouring the request's
``components`` as move_group does: scene settings (name, robot model), the robot state (the latest
``/joint_states``), the world objects' names, or their names and geometry. The cell's own geometry is
part of every plan but not listed, as MoveIt lists only objects added to the world.

The messages are made by :mod:`kinema.motion.planning_scene_messages`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from kinema.drivers.mujoco.names import JOINT_STATES_TOPIC, JOINT_STATES_TYPE
from kinema.motion.planning_scene_messages import planning_scene_dict, planning_scene_message
from kinema.runtime.names import (
    GET_PLANNING_SCENE,
    GET_PLANNING_SCENE_TYPE,
    PLANNING_SCENE,
    PLANNING_SCENE_TYPE,
)

if TYPE_CHECKING:
    from kinema.behaviors.context import BehaviorContext
    from kinema.motion import PlanningScene


def publish_planning_scene(context: BehaviorContext) -> None:
    """Publish ``context``'s planning scene (latched) on ``/monitored_planning_scene`` once a behavior
    makes it, and again on every change and every scene set in its place."""
    publisher = context.publisher(context.node, PLANNING_SCENE_TYPE, PLANNING_SCENE, latched=True)

    def publish(scene: PlanningScene) -> None:
        current = context.loaded_planning_scene
        if current is None or current is not scene:
            return  # a scene replaced since says nothing any more
        model = context.robot_model
        publisher.publish(planning_scene_message(current, str(getattr(model, "name", ""))))

    def follow(scene: PlanningScene) -> None:
        scene.subscribe(publish)
        publish(scene)

    context.on_planning_scene(follow)


def serve_planning_scene(node: Any, context: BehaviorContext) -> None:
    """Serve ``/get_planning_scene`` on ``node`` from the planning scene of ``context``, and publish it on
    ``/monitored_planning_scene`` (:func:`publish_planning_scene`).

    The scene is made at the first request if no behavior has used it yet; without a robot model the
    answer is an empty scene.
    """
    latest: list[Any] = [None]

    def on_joint_states(message: Any) -> None:
        latest[0] = message

    def on_request(request: Any) -> Any:
        from kinema.motion import PlanningScene

        model = context.robot_model
        scene = context.planning_scene if model is not None else PlanningScene()
        name = str(getattr(model, "name", "")) if model is not None else ""
        return {"scene": planning_scene_dict(scene, name, latest[0], int(request.components.components))}

    publish_planning_scene(context)
    node.create_subscription(JOINT_STATES_TYPE, JOINT_STATES_TOPIC, on_joint_states)
    node.create_service(GET_PLANNING_SCENE_TYPE, GET_PLANNING_SCENE, on_request)
