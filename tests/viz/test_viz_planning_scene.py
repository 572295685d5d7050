"""Collision objects of the planning scene become translucent shapes in the view, replaced on each update."""

from __future__ import annotations

import numpy as np
import umsgpack

from kinema.transport import from_dict
from kinema.viz.planning_scene import PlanningSceneLayer


def _scene(objects: list[dict]) -> object:
    return from_dict("moveit_msgs/msg/PlanningScene", {"world": {"collision_objects": objects}})


def _box(object_id: str, frame: str = "world") -> dict:
    return {
        "id": object_id,
        "header": {"frame_id": frame},
        "pose": {"position": {"x": 1.0, "y": 0.0, "z": 0.5}, "orientation": {"w": 1.0}},
        "primitives": [{"type": 1, "dimensions": [2.0, 1.0, 0.1]}, {"type": 3, "dimensions": [0.2, 0.05]}],
        "primitive_poses": [{"orientation": {"w": 1.0}}, {"position": {"z": 0.3}, "orientation": {"w": 1.0}}],
    }


def test_a_box_and_a_cylinder_are_drawn_where_the_object_is() -> None:
    layer = PlanningSceneLayer("/kinema/planning_scene")
    commands = layer.update(_scene([_box("virtual_table_top")]))
    assert commands[0][0] == "delete" and commands[0][1] == "/kinema/planning_scene"
    drawn = {path: umsgpack.unpackb(payload) for kind, path, payload in commands if kind == "set_object"}
    assert set(drawn) == {
        "/kinema/planning_scene/virtual_table_top/0",
        "/kinema/planning_scene/virtual_table_top/1",
    }
    box = drawn["/kinema/planning_scene/virtual_table_top/0"]["object"]
    assert box["geometries"][0]["type"] == "BoxGeometry"
    assert [box["geometries"][0][k] for k in ("width", "height", "depth")] == [2.0, 1.0, 0.1]
    assert box["materials"][0]["transparent"] is True
    moves = {
        path: umsgpack.unpackb(payload)["matrix"]
        for kind, path, payload in commands
        if kind == "set_transform"
    }
    box_pose = np.array(moves["/kinema/planning_scene/virtual_table_top/0"]).reshape(4, 4).T
    assert np.allclose(box_pose[:3, 3], [1.0, 0.0, 0.5])
    cylinder_pose = np.array(moves["/kinema/planning_scene/virtual_table_top/1"]).reshape(4, 4).T
    assert np.allclose(cylinder_pose[:3, 3], [1.0, 0.0, 0.8])
    assert np.allclose(cylinder_pose[:3, 1], [0, 0, 1])  # meshcat's cylinder axis (y) along the object's z


def test_an_update_replaces_what_was_drawn_and_unknown_frames_are_skipped() -> None:
    layer = PlanningSceneLayer("/root")
    layer.update(_scene([_box("a")]))
    commands = layer.update(_scene([_box("b", frame="nowhere"), _box("c")]), lambda frame: None)
    assert layer.object_ids == ["c"]
    assert [c[1] for c in commands if c[0] == "delete"] == ["/root"]
    assert not any(path.startswith("/root/b") for _, path, _ in commands)


def test_an_object_whose_pose_has_a_nan_is_skipped() -> None:
    bad = _box("bad")
    bad["pose"]["orientation"] = {"x": float("nan"), "w": 1.0}
    layer = PlanningSceneLayer("/root")
    layer.update(_scene([bad, _box("good")]))
    assert layer.object_ids == ["good"]


def test_an_attached_object_is_drawn_on_its_link_and_follows_it() -> None:
    scene = from_dict(
        "moveit_msgs/msg/PlanningScene",
        {
            "robot_state": {
                "attached_collision_objects": [
                    {
                        "link_name": "tool0",
                        "object": {
                            "id": "rod",
                            "header": {"frame_id": "tool0"},
                            "primitives": [{"type": 1, "dimensions": [0.04, 0.04, 0.4]}],
                            "primitive_poses": [{"position": {"z": 0.22}, "orientation": {"w": 1.0}}],
                        },
                    }
                ]
            }
        },
    )
    link = np.eye(4)
    link[:3, 3] = [0.5, 0.0, 1.0]
    poses = {"tool0": link}
    layer = PlanningSceneLayer("/root")
    commands = layer.update(scene, poses.get)
    moves = {p: umsgpack.unpackb(x)["matrix"] for kind, p, x in commands if kind == "set_transform"}
    shape = np.array(moves["/root/attached/rod/0"]).reshape(4, 4).T
    assert np.allclose(shape[:3, 3], [0, 0, 0.22])  # in the link's frame
    placed = np.array(moves["/root/attached/rod"]).reshape(4, 4).T
    assert np.allclose(placed[:3, 3], [0.5, 0.0, 1.0])
    assert layer.follow(poses.get) == []  # the link has not moved
    moved = link.copy()
    moved[:3, 3] = [0.6, 0.1, 0.9]
    (command,) = layer.follow({"tool0": moved}.get)
    assert command[1] == "/root/attached/rod"
    assert np.allclose(
        np.array(umsgpack.unpackb(command[2])["matrix"]).reshape(4, 4).T[:3, 3], [0.6, 0.1, 0.9]
    )
    assert layer.follow({}.get) == []  # a link the view does not know: left where it was
