"""The view follows the agent's planning scene: a latched /monitored_planning_scene becomes drawn shapes."""

from __future__ import annotations

import threading
import time
from typing import Any

from kinema.resources import bundled_dir
from kinema.runtime.names import PLANNING_SCENE as PLANNING_SCENE_TOPIC
from kinema.runtime.names import PLANNING_SCENE_TYPE
from kinema.transport import Node, from_dict, open_session
from kinema.viz.scene_model import SceneModel
from kinema.viz.scene_viewer import SceneViewer


class RecordingServer:
    """Stands in for the meshcat server: keeps every command the viewer sends."""

    def __init__(self) -> None:
        self.commands: list[tuple[str, str, bytes]] = []
        self._lock = threading.Lock()

    def send(self, commands: list[Any]) -> None:
        with self._lock:
            self.commands.extend(commands)

    def paths(self, kind: str) -> list[str]:
        with self._lock:
            return [path for k, path, _ in self.commands if k == kind]


def _scene(object_ids: list[str]) -> Any:
    return from_dict(
        PLANNING_SCENE_TYPE,
        {
            "world": {
                "collision_objects": [
                    {
                        "id": object_id,
                        "header": {"frame_id": "world"},
                        "pose": {"position": {"x": 0.7, "z": 1.0}, "orientation": {"w": 1.0}},
                        "primitives": [{"type": 1, "dimensions": [0.2, 0.2, 0.2]}],
                        "primitive_poses": [{"orientation": {"w": 1.0}}],
                    }
                    for object_id in object_ids
                ]
            }
        },
    )


def _wait(predicate: Any, what: str, timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return
        time.sleep(0.02)
    raise AssertionError(f"timed out waiting for {what}")


def test_a_scene_published_before_the_view_started_is_drawn_and_updates_replace_it() -> None:
    session = open_session([])
    publisher_node = Node(session, "agent_stand_in")
    server = RecordingServer()
    viewer = None
    try:
        publisher = publisher_node.create_publisher(PLANNING_SCENE_TYPE, PLANNING_SCENE_TOPIC, latched=True)
        publisher.publish(_scene(["virtual_table_top"]))  # before the view exists: latched
        model = SceneModel.from_file(bundled_dir("configs") / "lab_sim" / "description" / "lab_sim_scene.xml")
        viewer = SceneViewer(session, model, server)  # type: ignore[arg-type]
        viewer.start()
        box = "/kinema/planning_scene/virtual_table_top/0"
        _wait(lambda: box in server.paths("set_object"), "the latched table box to be drawn")
        publisher.publish(_scene(["in_front"]))
        _wait(lambda: "/kinema/planning_scene/in_front/0" in server.paths("set_object"), "the new box")
        assert server.paths("delete").count("/kinema/planning_scene") >= 2  # each update clears the layer
    finally:
        if viewer is not None:
            viewer.stop()
        publisher_node.close()
        session.close()


def test_frames_heard_on_tf_place_markers_through_their_parent() -> None:
    import numpy as np

    session = open_session([])
    publisher_node = Node(session, "tf_stand_in")
    viewer = None
    try:
        model = SceneModel.from_file(bundled_dir("configs") / "lab_sim" / "description" / "lab_sim_scene.xml")
        viewer = SceneViewer(session, model, RecordingServer())  # type: ignore[arg-type]
        viewer.start()
        assert viewer.frame_pose("local") is None
        tf = publisher_node.create_publisher("tf2_msgs/msg/TFMessage", "/tf")
        message = from_dict(
            "tf2_msgs/msg/TFMessage",
            {
                "transforms": [
                    {
                        "header": {"frame_id": "tray"},
                        "child_frame_id": "local",
                        "transform": {"translation": {"z": 0.1}, "rotation": {"w": 1.0}},
                    }
                ]
            },
        )

        def heard() -> bool:
            tf.publish(message)
            return viewer.frame_pose("local") is not None

        _wait(heard, "the frame on /tf")
        tray = model.frame_pose("tray")
        assert tray is not None
        np.testing.assert_allclose(viewer.frame_pose("local")[:3, 3], tray[:3, 3] + tray[:3, 2] * 0.1)
    finally:
        if viewer is not None:
            viewer.stop()
        publisher_node.close()
        session.close()
