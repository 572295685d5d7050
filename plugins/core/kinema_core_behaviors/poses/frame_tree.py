"""The frame tree a behavior sees now: robot links at the current joint state (the latest ``/joint_states``
through the robot model: ``world``, ``base_link``, ``tool0``, ``grasp_link``, ...), and the cell's other
frames, ``context.frames`` (:class:`kinema.motion.cell_frames.CellFrames`: cameras, simulated objects,
planning-scene objects).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

from kinema.errors import KinemaError, ObjectiveError

from ..motion.joint_states import joint_state_monitor
from ..motion.planning_resources import robot_model


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
    name = getattr(behavior, "registration_id", type(behavior).__name__)
    model = robot_model(behavior.context, name)
    if joint_state is None:
        q = joint_state_monitor(behavior.context, name).positions_at(model.joint_names, at)
    else:
        q = _positions_from(behavior, model, joint_state)
    return behavior.context.frames.tree(q)


def _positions_from(behavior: Any, model: Any, joint_state: Any) -> np.ndarray:
    import numpy as np

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
