"""Where a robot's description files are, and loading the planning side (model + scene) from them."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from kinema.errors import MotionError
from kinema.motion.planning_scene import PlanningScene
from kinema.motion.robot_model import RobotModel


@dataclass(frozen=True)
class RobotDescription:
    """Paths of the files that describe one robot cell.

    Attributes:
        urdf: the robot for planning.
        srdf: planning groups, end effector, disabled collision pairs.
        joint_limits: MoveIt-format joint_limits.yaml (velocity and acceleration limits).
        mjcf: the MuJoCo scene (robot plus world); its static geoms become the planning scene.
    """

    urdf: Path
    srdf: Path
    joint_limits: Path
    mjcf: Path | None = None

    @classmethod
    def lab_sim(cls) -> RobotDescription:
        """The bundled lab_sim cell (``configs/lab_sim/description``)."""
        from kinema.resources import bundled_dir

        d = bundled_dir("configs") / "lab_sim" / "description"
        return cls(d / "lab_sim.urdf", d / "lab_sim.srdf", d / "joint_limits.yaml", d / "lab_sim_scene.xml")

    def load_model(self) -> RobotModel:
        """Build the :class:`RobotModel` from the URDF, SRDF and joint limits.

        Raises:
            MotionError: a file is missing or malformed.
        """
        for label, path in (("URDF", self.urdf), ("SRDF", self.srdf), ("joint limits", self.joint_limits)):
            if not Path(path).is_file():
                raise MotionError(f"{label} file not found: {path}")
        return RobotModel.from_urdf(self.urdf, self.srdf, self.joint_limits)

    def load_scene(self, model: RobotModel) -> PlanningScene:
        """The planning scene: the static geoms of the MJCF scene (an empty scene without one)."""
        if self.mjcf is None:
            return PlanningScene()
        if not Path(self.mjcf).is_file():
            raise MotionError(f"MuJoCo scene file not found: {self.mjcf}")
        return PlanningScene.from_mjcf(self.mjcf, model.link_names)
