"""The 3D view starts from the front, on the robot and its workspace, whole, at every page load."""

from __future__ import annotations

import numpy as np
import pytest
import umsgpack

mujoco = pytest.importorskip("mujoco")

from kinema.config import resolve_config  # noqa: E402
from kinema.viz.scene_model import SceneModel  # noqa: E402


def _lab_sim() -> SceneModel:
    resolved = resolve_config("lab_sim")
    path = resolved.mujoco_model_path
    assert path is not None
    keyframe = resolved.get("hardware.simulation.mujoco_keyframe")
    return SceneModel(mujoco.MjModel.from_xml_path(str(path)), keyframe=keyframe)


def _in_view(view: dict[str, object], points: np.ndarray) -> np.ndarray:
    """Angle (deg) of each point off the camera's axis."""
    position = np.asarray(view["position"])
    axis = np.asarray(view["target"]) - position
    axis /= np.linalg.norm(axis)
    rays = points - position
    rays /= np.linalg.norm(rays, axis=1)[:, None]
    return np.degrees(np.arccos(np.clip(rays @ axis, -1, 1)))


def test_lab_sim_is_seen_from_its_scene_cameras_side_with_the_arm_whole_and_large() -> None:
    scene = _lab_sim()
    view = scene.camera_view()["camera"]
    forward = np.subtract(view["target"], view["position"])
    forward /= np.linalg.norm(forward)
    # The scene camera's direction: from the front of the table (+y), looking down across it at the robot.
    np.testing.assert_allclose(forward, np.array([0.0, -1.6, -1.05]) / np.hypot(1.6, 1.05), atol=1e-6)
    assert view["fov"] == 55.0
    model, data = scene.model, scene.data
    arm = [b for b in range(model.nbody) if int(model.body_weldid[b]) != 0]
    angles = _in_view(view, np.asarray(data.xpos[arm]))
    assert angles.max() < view["fov"] / 2, angles  # every moving body is in the picture
    # ... and the picture is about them: the 3 m rail and the table do not set the distance.
    distance = np.linalg.norm(np.subtract(view["target"], view["position"]))
    assert distance < 2.0, distance


def test_a_scene_without_a_fixed_camera_is_framed_from_its_free_cameras_direction() -> None:
    xml = """
    <mujoco>
      <visual><global azimuth="90" elevation="-30" fovy="45"/></visual>
      <worldbody>
        <geom type="plane" size="0 0 1"/>
        <geom name="shelf" type="box" size="3 0.2 1" pos="0 5 1"/>
        <body name="link" pos="1 0 0.5"><joint type="hinge"/><geom type="capsule" size="0.05 0.3"/></body>
      </worldbody>
    </mujoco>
    """
    scene = SceneModel(mujoco.MjModel.from_xml_string(xml))
    view = scene.camera_view()["camera"]
    forward = np.subtract(view["target"], view["position"])
    forward /= np.linalg.norm(forward)
    expected = np.array([0.0, np.cos(np.radians(30)), -np.sin(np.radians(30))])
    np.testing.assert_allclose(forward, expected, atol=1e-6)
    np.testing.assert_allclose(view["target"][:2], [1.0, 0.0], atol=1e-6)  # the link, not the far shelf
    assert view["fov"] == 45.0


def test_mesh_geoms_are_drawn_as_meshes() -> None:
    # A robot from a URDF with visual meshes: its links are mesh geoms, drawn as their triangles.
    xml = """
    <mujoco>
      <asset>
        <mesh name="base" vertex="0 0 0  0.2 0 0  0 0.2 0  0 0 0.3"/>
        <mesh name="link" vertex="0 0 0  0.1 0 0  0 0.1 0  0 0 0.5"/>
      </asset>
      <worldbody>
        <geom name="base_visual" type="mesh" mesh="base"/>
        <body name="link1" pos="0 0 0.3">
          <joint type="hinge"/><geom name="link1_visual" type="mesh" mesh="link"/>
        </body>
      </worldbody>
    </mujoco>
    """
    scene = SceneModel(mujoco.MjModel.from_xml_string(xml))
    drawn = {}
    for kind, path, payload in scene.scene_commands():
        if kind == "set_object":
            message = umsgpack.unpackb(payload)
            drawn[path] = message["object"]["geometries"][0]["type"]
    meshes = {path: kind for path, kind in drawn.items() if "visual" in path}
    assert len(meshes) == 2 and set(meshes.values()) == {"BufferGeometry"}, drawn


def test_kinema_view_draws_and_names_the_config_the_runtime_runs(tmp_path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    # `kinema run -c example_config` in a workspace; `kinema view` attached to it (no -c) said lab_sim.
    from kinema.runtime import instance
    from kinema.viz.view import resolve_scene

    record = instance.InstanceRecord(
        pid=1, router="tcp/localhost:17447", run_folder=str(tmp_path), config="example_config"
    )
    monkeypatch.setattr(instance, "running_instances", lambda: [record])
    monkeypatch.delenv("KINEMA_CONFIG", raising=False)
    source = resolve_scene(None, None, "tcp/127.0.0.1:17447")
    assert source.config == "example_config"
