"""The frame tree: where every named frame of the cell is, as ``world_T_frame``.

Frames come from three places, in this order of precedence:

1. the robot model at a configuration (every URDF link and frame: ``world``, ``base_link``, ``tool0``,
   ``grasp_link``, ...);
2. named fixed frames given by the caller: simulated objects (``cube``), cameras (``scene_camera``),
   planning-scene objects, each as a 4x4 pose in the world;
3. ``world`` and the empty frame id, which are the world itself.

Poses are homogeneous transforms of shape ``(4, 4)`` in metres; ``a_T_b`` is frame ``b`` seen from ``a``.
A lookup of a frame nobody knows raises :class:`MotionError` listing the closest known names.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from kinema.errors import MotionError, did_you_mean

if TYPE_CHECKING:
    from kinema.motion.robot_model import RobotModel

WORLD_FRAMES = ("", "world")


class FrameTree:
    """Named frames of the robot (at configuration ``q``) and of the world around it.

    Args:
        model: the robot model, or None for a tree of fixed frames only.
        q: the robot's configuration, shape ``(n,)`` over ``model.joint_names``.
        fixed: other frames, name -> ``world_T_frame`` (objects, cameras); robot links win on a clash.
    """

    def __init__(
        self,
        model: RobotModel | None = None,
        q: np.ndarray | None = None,
        fixed: Mapping[str, np.ndarray] | None = None,
    ) -> None:
        self.model = model
        self.q = None if q is None else np.asarray(q, dtype=float)
        self._fixed = {str(k): np.asarray(v, dtype=float) for k, v in (fixed or {}).items()}
        self._robot: dict[str, np.ndarray] | None = None

    def _robot_frames(self) -> dict[str, np.ndarray]:
        if self._robot is None:
            self._robot = {}
            if self.model is not None and self.q is not None:
                import pinocchio as pin

                data = self.model.new_data()
                pin.framesForwardKinematics(self.model.pin_model, data, self.model.pin_configuration(self.q))
                for i, frame in enumerate(self.model.pin_model.frames):
                    if frame.name != "universe":
                        self._robot[frame.name] = np.array(data.oMf[i].homogeneous)
        return self._robot

    def names(self) -> list[str]:
        """Every frame this tree can resolve (``world`` first)."""
        names = ["world", *self._robot_frames()]
        names += [n for n in self._fixed if n not in names]
        return list(dict.fromkeys(names))

    def __contains__(self, frame: object) -> bool:
        return isinstance(frame, str) and (
            frame in WORLD_FRAMES or frame in self._robot_frames() or frame in self._fixed
        )

    def world_T(self, frame: str) -> np.ndarray:
        """``world_T_frame``, shape ``(4, 4)``.

        Raises:
            MotionError: no frame of that name (with the closest names there are).
        """
        if frame in WORLD_FRAMES:
            return np.eye(4)
        robot = self._robot_frames()
        if frame in robot:
            return robot[frame].copy()
        if frame in self._fixed:
            return self._fixed[frame].copy()
        raise MotionError(f"unknown frame {frame!r}; {did_you_mean(frame, self.names())}")

    def transform(self, source_T_pose: np.ndarray, source: str, target: str) -> np.ndarray:
        """Express a pose given in frame ``source`` in frame ``target``: ``target_T_pose``."""
        world_T_pose = self.world_T(source) @ np.asarray(source_T_pose, dtype=float)
        return np.linalg.inv(self.world_T(target)) @ world_T_pose
