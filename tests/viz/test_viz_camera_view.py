"""The 3D view starts from lab_sim's scene camera, which sits in a world-fixed body of its own."""

from __future__ import annotations

import numpy as np

from kinema.config import resolve_config
from kinema.viz.scene_model import SceneModel


def test_the_view_starts_where_the_scene_camera_stands_looking_where_it_looks() -> None:
    import mujoco

    path = resolve_config("lab_sim").mujoco_model_path
    assert path is not None
    model = mujoco.MjModel.from_xml_path(str(path))
    view = SceneModel(model).camera_view()["camera"]
    np.testing.assert_allclose(view["position"], [0.0, 2.1, 1.624], atol=1e-9)
    forward = np.subtract(view["target"], view["position"])
    forward /= np.linalg.norm(forward)
    # The scene camera looks down across the table at the robot: along (0, -1.6, -1.05).
    np.testing.assert_allclose(forward, np.array([0.0, -1.6, -1.05]) / np.hypot(1.6, 1.05), atol=1e-6)
    assert view["fov"] == 55.0
