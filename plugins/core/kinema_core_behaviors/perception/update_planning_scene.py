"""UpdatePlanningSceneService: a point cloud becomes obstacles in the planning scene (MoveIt's octomap).

MoveIt Pro sends the cloud to its octomap updater's service; Kinema's planning scene lives in the agent,
so the behavior fills it directly: the cloud, in the world frame, is cut into cubes of
``OCTOMAP_RESOLUTION``; cubes that hold points become box obstacles of the world object ``octomap``
(replacing the previous ones). Cubes on the robot (its links at the current joint state, padded) and on
obstacles the scene already has are left out. ClearSnapshot's subtree, ResetPlanningSceneObjects or a
new cloud remove them.
"""

from __future__ import annotations

from kinema.behaviors import AsyncBehavior, PortInfo, input_port
from kinema.errors import KinemaError

from ..messages.ports import fails_on_bad_input, message_input, read_input
from ..motion.joint_states import joint_state_monitor
from ..motion.planning_resources import collision_checker, robot_model
from .clouds import POINT_CLOUD, frame_of, read_cloud, target_T_source

OCTOMAP_ID = "octomap"
# Side of the occupancy cubes, m: MoveIt's octomap default resolution is 2.5 cm; 5 cm keeps the number of
# boxes (each checked against every link) small enough for planning to stay interactive.
OCTOMAP_RESOLUTION = 0.05
# A cube needs this many points to count as occupied (a stray pixel does not block the robot).
MIN_POINTS = 3
# Points this close to a robot link's bounds are the robot itself.
SELF_FILTER_PADDING = 0.05
# The most cubes one cloud may add; beyond it the behavior fails instead of making planning crawl.
MAX_CELLS = 4000


class UpdatePlanningSceneService(AsyncBehavior):
    """Adds what ``point_cloud`` shows to the planning scene as obstacles (world object ``octomap``).

    Later plans keep clear of them; ``kinema view`` draws them as boxes. ``point_cloud_service`` names
    MoveIt Pro's octomap service; Kinema's scene needs no service, so it is only checked to be set.
    Fails on an empty cloud, a cloud whose frame the cell does not know, or more than ``MAX_CELLS`` cubes.
    """

    subcategory = "Perception - Planning Scene"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input("point_cloud", POINT_CLOUD, "{point_cloud}", "The cloud to add to the scene."),
            input_port(
                "point_cloud_service",
                str,
                "/point_cloud_service",
                "MoveIt Pro's octomap updater service (Kinema fills its scene directly).",
            ),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        import numpy as np

        from kinema.motion import CollisionObject
        from kinema.perception.occupancy import aabb_of_box, occupied_cells, outside_boxes

        cloud = read_cloud(self, "point_cloud")
        read_input(self, "point_cloud_service")
        world = cloud.transformed(target_T_source(self, frame_of(cloud), "world", "point_cloud"), "world")
        cells = occupied_cells(world.points, OCTOMAP_RESOLUTION, MIN_POINTS)
        try:
            model = robot_model(self.context, "UpdatePlanningSceneService")
            scene = self.context.planning_scene
            q = joint_state_monitor(self.context, "UpdatePlanningSceneService").positions(model.joint_names)
            checker = collision_checker(self.context, "UpdatePlanningSceneService", 0.0)
            robot = checker.robot_bounds(q)
            known = [
                aabb_of_box(o.world_T_object, o.size if o.shape == "box" else (max(o.size),) * 3)
                for name, o in scene.objects.items()
                if name not in scene.world.get(OCTOMAP_ID, ())
            ]
            cells = outside_boxes(cells, robot, SELF_FILTER_PADDING)
            cells = outside_boxes(cells, known, OCTOMAP_RESOLUTION / 2)
            if len(cells) > MAX_CELLS:
                self.logger.publish_failure(
                    f"UpdatePlanningSceneService: the cloud fills {len(cells)} cubes of "
                    f"{OCTOMAP_RESOLUTION} m, more than {MAX_CELLS}; crop it first (CropPointsInBox)"
                )
                return False
            half = (OCTOMAP_RESOLUTION / 2,) * 3
            boxes = []
            for centre in cells:
                pose = np.eye(4)
                pose[:3, 3] = centre
                boxes.append(CollisionObject(OCTOMAP_ID, "box", half, pose))
            if boxes:
                scene.add_world_object(OCTOMAP_ID, boxes, replace=True)
            elif OCTOMAP_ID in scene.world:
                scene.remove_world_object(OCTOMAP_ID)
        except KinemaError as error:
            self.logger.publish_failure(f"UpdatePlanningSceneService: {error}")
            return False
        self.logger.publish_info(
            f"UpdatePlanningSceneService: {len(boxes)} occupied cubes of {OCTOMAP_RESOLUTION} m "
            "in the planning scene"
        )
        return True
