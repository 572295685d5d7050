"""What the URDF behaviors share: finding a URDF object of the planning scene, the frame tree now."""

from __future__ import annotations

from typing import Any

from kinema.errors import MotionError, did_you_mean


def urdf_in_world(node: Any, name: str) -> None:
    """Raise unless ``name`` is a URDF object of the planning scene that is not attached.

    Raises:
        MotionError: naming the URDF objects there are, or saying it is attached (and to what).
    """
    scene = node.context.planning_scene
    attached = scene.attached_objects().get(name)
    if attached is not None:
        raise MotionError(f"URDF object {name!r} is attached to {attached.link!r}; DetachURDF it first")
    if name not in scene.urdf_ids or name not in scene.world:
        raise MotionError(
            f"no URDF object {name!r} in the planning scene (AddURDF adds one); {known(scene, name)}"
        )


def known(scene: Any, name: str) -> str:
    """The URDF objects of ``scene``, closest to ``name`` first, for an error message."""
    ids = sorted(scene.urdf_ids)
    return did_you_mean(name, ids) if ids else "there is none"


def world_T_link(node: Any, link: str) -> Any:
    """Where robot link ``link`` is now (the latest joint state).

    Raises:
        MotionError: ``link`` is no link of the robot (naming the close ones).
    """
    from ..motion.planning_resources import robot_model
    from ..poses.frame_tree import current_frame_tree

    model = robot_model(node.context, node.registration_id)
    if link not in model.link_names:
        raise MotionError(f"{link!r} is no link of the robot; {did_you_mean(link, model.link_names)}")
    return current_frame_tree(node).world_T(link)
