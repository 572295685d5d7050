"""The perception behaviors on lab_sim's rendered cameras: the microscope's CAD model registered onto the
scene camera's cloud lands on the simulated microscope, and a mask of the cube's pixels picks the cube's
points and box out of the cloud.

They need OpenGL (EGL headless); without it they skip with the packages to install.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.drivers.mujoco.cameras import GL_HELP
from kinema.perception.ros_messages import image_array
from kinema.testing import tick_behavior
from kinema.transport import from_dict

pytestmark = pytest.mark.slow


# The first frame after a subscription can take over the 5 s default on a loaded machine (the driver,
# the agent's behaviors and the test share one process here): a bound for a real failure only.
SLOW_FIRST_FRAME = {"message_timeout_sec": 60.0}


@pytest.fixture(scope="module")
def cameras(driver: Any) -> Any:
    cameras = driver.cameras
    assert cameras is not None, "lab_sim has cameras, the driver serves none"
    assert cameras.ready.wait(60), "the camera thread did not get ready within 60 s"
    if cameras.unavailable is not None:
        pytest.skip(f"no OpenGL for MuJoCo ({cameras.unavailable}). {GL_HELP}")
    return cameras


def _body_pose(driver: Any, body: str) -> np.ndarray:
    def read() -> np.ndarray:
        pose = np.eye(4)
        pose[:3, :3] = driver.data.body(body).xmat.reshape(3, 3)
        pose[:3, 3] = driver.data.body(body).xpos
        return pose

    return driver.simulation.call(read)


def _pose_message(matrix: np.ndarray) -> Any:
    x, y, z, w = Rotation.from_matrix(matrix[:3, :3]).as_quat()
    px, py, pz = matrix[:3, 3]
    return from_dict(
        "geometry_msgs/msg/PoseStamped",
        {
            "header": {"frame_id": "world"},
            "pose": {
                "position": {"x": px, "y": py, "z": pz},
                "orientation": {"x": x, "y": y, "z": z, "w": w},
            },
        },
    )


def _matrix(pose: Any) -> np.ndarray:
    p, o = pose.pose.position, pose.pose.orientation
    matrix = np.eye(4)
    matrix[:3, :3] = Rotation.from_quat([o.x, o.y, o.z, o.w]).as_matrix()
    matrix[:3, 3] = [p.x, p.y, p.z]
    return matrix


def _ok(run: Any) -> Any:
    assert run.status == NodeStatus.SUCCESS, run.toasts
    return run.outputs


def _camera_message(behavior: Any, context: BehaviorContext, behavior_id: str, topic: str) -> Any:
    """The next message of ``topic``, taken by the camera behavior ``behavior_id`` (GetImage, ...)."""
    inputs = {"topic_name": topic, **SLOW_FIRST_FRAME}
    return _ok(tick_behavior(behavior(behavior_id), inputs, context=context, timeout=60))["message_out"]


def test_the_microscope_cad_model_registers_onto_the_scene_camera_cloud(
    behavior: Any, context: BehaviorContext, driver: Any, cameras: Any
) -> None:
    truth = _body_pose(driver, "microscope")
    cloud = _camera_message(behavior, context, "GetPointCloud", "/scene_camera/points")
    world = _ok(
        tick_behavior(
            behavior("TransformPointCloudFrame"), {"input_cloud": cloud}, context=context, timeout=30
        )
    )["output_cloud"]
    around = truth.copy()
    around[:3, 3] += [0.0, 0.0, 0.15]
    seen = _ok(
        tick_behavior(
            behavior("CropPointsInBox"),
            {
                "point_cloud": world,
                "crop_box_centroid_pose": _pose_message(around),
                "crop_box_size": "0.4;0.4;0.29",
            },
            context=context,
        )
    )["point_cloud_cropped"]
    assert seen.width > 500, f"the scene camera sees only {seen.width} points of the microscope"
    model = _ok(
        tick_behavior(
            behavior("LoadPointCloudFromFile"),
            {"package_name": "lab_sim", "file_path": "description/assets/microscope.stl", "random_seed": 1},
            context=context,
        )
    )["point_cloud"]
    # The guess is off by 3 cm and 8 degrees, as a hand-measured pose would be.
    offset = np.eye(4)
    offset[:3, :3] = Rotation.from_euler("z", 8, degrees=True).as_matrix()
    offset[:3, 3] = [0.03, -0.02, 0.0]
    guess = truth @ offset
    placed = _ok(
        tick_behavior(
            behavior("TransformPointCloud"),
            {"input_cloud": model, "transform_pose": _pose_message(guess)},
            context=context,
        )
    )["output_cloud"]
    correction = _ok(
        tick_behavior(
            behavior("RegisterPointClouds"),
            {
                "base_point_cloud": placed,
                "target_point_cloud": seen,
                "max_correspondence_distance": 0.05,
                "max_iterations": 100,
            },
            context=context,
            timeout=60,
        )
    )["target_pose_in_base_frame"]
    found = _matrix(correction) @ guess
    error = np.linalg.norm(found[:3, 3] - truth[:3, 3])
    angle = np.degrees(Rotation.from_matrix(found[:3, :3].T @ truth[:3, :3]).magnitude())
    assert error < 0.005 and angle < 1.0, (
        f"registered microscope {error * 1000:.1f} mm and {angle:.1f} deg from the simulated one "
        f"(the guess was {np.linalg.norm(guess[:3, 3] - truth[:3, 3]) * 1000:.0f} mm and 8 deg off)"
    )


def test_a_mask_of_the_cubes_pixels_picks_the_cube_out_of_the_cloud(
    behavior: Any, context: BehaviorContext, driver: Any, cameras: Any
) -> None:
    cube = _body_pose(driver, "cube")[:3, 3]
    info = _camera_message(behavior, context, "GetCameraInfo", "/scene_camera/camera_info")
    image = _camera_message(behavior, context, "GetImage", "/scene_camera/color")
    cloud = _camera_message(behavior, context, "GetPointCloud", "/scene_camera/points")
    pixels = image_array(image).astype(int)
    red = (pixels[..., 0] > 120) & (pixels[..., 1] < 80) & (pixels[..., 2] < 80)
    rows, cols = np.nonzero(red)
    assert len(rows) > 50, f"only {len(rows)} red pixels: the scene camera does not see the cube"
    # What a segmentation model would give: the cube's pixels inside their bounding box.
    y0, x0 = rows.min(), cols.min()
    layer = red[y0 : rows.max() + 1, x0 : cols.max() + 1].astype(np.uint8) * 255
    height, width = layer.shape
    mask = from_dict(
        "moveit_studio_vision_msgs/msg/Mask2D",
        {
            "x": int(x0),
            "y": int(y0),
            "mask": {
                "height": height,
                "width": width,
                "encoding": "mono8",
                "step": width,
                "data": layer.reshape(-1),
            },
        },
    )
    masks3d = _ok(
        tick_behavior(
            behavior("GetMasks3DFromMasks2D"),
            {"point_cloud": cloud, "camera_info": info, "masks2d": [mask]},
            context=context,
        )
    )["masks3d"]
    fragment = _ok(
        tick_behavior(
            behavior("GetPointCloudFromMask3D"), {"point_cloud": cloud, "mask3d": masks3d[0]}, context=context
        )
    )["point_cloud_fragment"]
    in_world = _ok(
        tick_behavior(
            behavior("TransformPointCloudFrame"), {"input_cloud": fragment}, context=context, timeout=30
        )
    )["output_cloud"]
    centre = _ok(
        tick_behavior(behavior("GetCentroidFromPointCloud"), {"point_cloud": in_world}, context=context)
    )["output_pose"]
    p = centre.pose.position
    # The scene camera looks down on the cube: the points are mostly its top face, centred over it.
    assert np.hypot(p.x - cube[0], p.y - cube[1]) < 0.01 and cube[2] < p.z < cube[2] + 0.028, (
        f"centroid of the masked points {[p.x, p.y, p.z]}, cube at {cube.tolist()}"
    )
    shapes = _ok(
        tick_behavior(
            behavior("FindMaskedObjects"),
            {"point_cloud": cloud, "camera_info": info, "masks2d": [mask], "base_frame": "world"},
            context=context,
            timeout=30,
        )
    )["detected_shapes"]
    (found,) = shapes
    size = sorted(found.object.primitives[0].dimensions)
    assert size == pytest.approx([0.05, 0.05, 0.05], abs=0.01), f"the cube's box is {size}, not 5 cm"
