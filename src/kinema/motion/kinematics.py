"""Forward kinematics: where a link or frame of the robot is for a configuration."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import pinocchio as pin

    from kinema.motion.robot_model import RobotModel


def fk(model: RobotModel, q: np.ndarray, frame: str, data: pin.Data | None = None) -> np.ndarray:
    """Return ``world_T_frame``, the pose of ``frame`` in the URDF root (world) frame.

    Args:
        model: the robot model.
        q: configuration, shape ``(n,)`` over ``model.joint_names`` (m / rad).
        frame: a link or frame name of the URDF (e.g. ``"grasp_link"``).
        data: pinocchio scratch data to reuse (``model.new_data()``); a fresh one when omitted.

    Returns:
        A homogeneous transform, shape ``(4, 4)``, translation in metres.

    Raises:
        MotionError: unknown frame (the message lists the valid link names).
    """
    import pinocchio as pin

    fid = model.frame_id(frame)
    data = data if data is not None else model.new_data()
    pin.framesForwardKinematics(model.pin_model, data, model.pin_configuration(np.asarray(q, dtype=float)))
    return np.array(data.oMf[fid].homogeneous)


def frame_poses(model: RobotModel, q: np.ndarray, data: pin.Data | None = None) -> dict[str, np.ndarray]:
    """Return ``world_T_link`` (shape ``(4, 4)``) for every link of the robot at configuration ``q``."""
    import pinocchio as pin

    data = data if data is not None else model.new_data()
    pin.framesForwardKinematics(model.pin_model, data, model.pin_configuration(np.asarray(q, dtype=float)))
    return {
        f.name: np.array(data.oMf[i].homogeneous)
        for i, f in enumerate(model.pin_model.frames)
        if f.type == pin.FrameType.BODY
    }
