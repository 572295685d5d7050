"""GetPoseFromPixelCoords: clicked pixels of a camera's organised cloud become poses on the surface there,
z out of the surface towards the camera, ready for push_button.xml's TransformPose approach offset."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from kinema.bt import NodeStatus
from kinema.perception import PointCloud
from kinema.perception.ros_messages import to_point_cloud2
from kinema.testing import tick_behavior
from kinema.transforms import pose_from_message
from kinema.transport import from_dict

CAMERA = "wrist_camera_optical_frame"
WIDTH, HEIGHT, FOCAL = 64, 48, 60.0
# A plane 1 m in front of the camera, tilted about both image axes; its normal faces the camera.
PLANE_POINT = np.array([0.0, 0.0, 1.0])
NORMAL = np.array([0.3, -0.2, -1.0]) / np.linalg.norm([0.3, -0.2, -1.0])


def _types() -> Any:
    from kinema.interfaces import load_interfaces

    return load_interfaces().typestore.types


def tilted_plane() -> np.ndarray:
    """The organised HxWx3 points (m, optical frame: x right, y down, z forward) a pinhole camera sees of
    the plane, each pixel's ray cut with it."""
    u, v = np.meshgrid(np.arange(WIDTH), np.arange(HEIGHT))
    rays = np.stack(
        [(u - (WIDTH - 1) / 2) / FOCAL, (v - (HEIGHT - 1) / 2) / FOCAL, np.ones(u.shape)], axis=-1
    )
    depth = float(NORMAL @ PLANE_POINT) / (rays @ NORMAL)
    return rays * depth[..., None]


def cloud_message(points: np.ndarray, organised: bool = True) -> Any:
    flat = np.asarray(points, dtype=np.float32).reshape(-1, 3)
    shape = (points.shape[0], points.shape[1]) if organised else None
    return to_point_cloud2(PointCloud(flat, None, CAMERA, 0.0, shape), _types())


def pixels(*uv: tuple[float, float]) -> list[Any]:
    """``pixel_coords`` as GetPointsFromUser writes them: PointStamped x the column, y the row."""
    return [
        from_dict(
            "geometry_msgs/msg/PointStamped",
            {"header": {"frame_id": f"point_{i + 1}"}, "point": {"x": float(u), "y": float(v), "z": 0.0}},
        )
        for i, (u, v) in enumerate(uv)
    ]


def run(behavior: Any, cloud: Any, coords: list[Any], **ports: Any) -> Any:
    inputs = {"point_cloud": cloud, "pixel_coords": coords, **ports}
    return tick_behavior(behavior("GetPoseFromPixelCoords"), inputs)


def test_each_pixel_gives_a_pose_at_its_point_with_z_along_the_normal_towards_the_camera(
    behavior: Any,
) -> None:
    points = tilted_plane()
    clicked = [(10, 5), (32, 24), (60, 40)]
    result = run(behavior, cloud_message(points), pixels(*clicked), downsample_fraction=0.1)
    assert result.status == NodeStatus.SUCCESS, result.toasts
    poses = result.outputs["output_poses"]
    assert len(poses) == len(clicked)
    for (u, v), stamped in zip(clicked, poses, strict=True):
        assert stamped.header.frame_id == CAMERA
        pose = pose_from_message(stamped.pose)
        assert np.allclose(pose[:3, 3], points[v, u], atol=1e-6)
        assert np.allclose(pose[:3, 2], NORMAL, atol=1e-3), (u, v, pose[:3, 2])
        assert float(pose[:3, 2] @ -pose[:3, 3]) > 0, "z points towards the camera"
        assert pose[0, 0] > 0.9, "x is the image's right, laid into the surface"


def test_a_half_pixel_rounds_to_the_nearest_and_the_whole_cloud_may_be_used(behavior: Any) -> None:
    points = tilted_plane()
    result = run(behavior, cloud_message(points), pixels((31.6, 7.4)), downsample_fraction=1.0)
    assert result.status == NodeStatus.SUCCESS, result.toasts
    assert np.allclose(pose_from_message(result.outputs["output_poses"][0].pose)[:3, 3], points[7, 32])


def test_push_buttons_transform_pose_makes_an_approach_facing_the_surface(behavior: Any) -> None:
    points = tilted_plane()
    found = run(behavior, cloud_message(points), pixels((20, 30)))
    assert found.status == NodeStatus.SUCCESS, found.toasts
    approach = tick_behavior(
        behavior("TransformPose"),
        {
            "input_pose": found.outputs["output_poses"][0],
            "quaternion_xyzw": "0.7071;0.7071;0;0",
            "translation_xyz": "0;0;0.1",
        },
    )
    assert approach.status == NodeStatus.SUCCESS, approach.toasts
    pose = pose_from_message(approach.outputs["output_pose"].pose)
    assert np.allclose(pose[:3, 3], points[30, 20] + 0.1 * NORMAL, atol=1e-3)
    # ...facing it: the approach's z points into the surface, as a tool's should.
    assert np.allclose(pose[:3, 2], -NORMAL, atol=1e-3)


def test_a_point_on_the_other_side_of_the_camera_still_faces_it(behavior: Any) -> None:
    """The sign of the normal follows the camera, not the PCA's arbitrary eigenvector sign."""
    points = tilted_plane()
    points[..., 0] *= -1.0  # the mirror image: normal (-0.3, -0.2, -1)
    result = run(behavior, cloud_message(points), pixels((5, 5), (50, 40)))
    assert result.status == NodeStatus.SUCCESS, result.toasts
    mirrored = NORMAL * [-1.0, 1.0, 1.0]
    for stamped in result.outputs["output_poses"]:
        assert np.allclose(pose_from_message(stamped.pose)[:3, 2], mirrored, atol=1e-3)


@pytest.mark.parametrize(
    ("coords", "ports", "says"),
    [
        (pixels((12, 9)), {}, "pixel 0 (point_1) at column 12, row 9: the camera saw nothing there (NaN)"),
        (pixels((3, 3), (64, 10)), {}, "pixel 1 (point_2) at column 64, row 10 is outside the cloud's 64x48"),
        (pixels((3, -1)), {}, "at column 3, row -1 is outside"),
        (pixels((3, 3)), {"downsample_fraction": 0.0}, "port [downsample_fraction] = 0; give a fraction"),
        (pixels((3, 3)), {"downsample_fraction": 1.5}, "port [downsample_fraction] = 1.5; give a fraction"),
        (pixels((3, 3)), {"neighbor_radius": 0.0}, "port [neighbor_radius] = 0"),
        (pixels((3, 3)), {"neighbor_radius": 1e-4}, "too few points to fit a surface: 1"),
        ([], {}, "port [pixel_coords] is empty"),
        (["3;3"], {}, "element 0 is not a geometry_msgs/msg/PointStamped"),
    ],
)
def test_bad_pixels_and_ports_fail_saying_which(
    behavior: Any, coords: list[Any], ports: dict[str, Any], says: str
) -> None:
    points = tilted_plane()
    points[9, 12] = np.nan
    result = run(behavior, cloud_message(points), coords, **ports)
    assert result.status == NodeStatus.FAILURE
    assert says in result.toasts[-1], result.toasts


def test_an_unorganised_cloud_has_no_pixels(behavior: Any) -> None:
    result = run(behavior, cloud_message(tilted_plane(), organised=False), pixels((3, 3)))
    assert result.status == NodeStatus.FAILURE
    assert "is unorganised" in result.toasts[-1] and "organised cloud" in result.toasts[-1], result.toasts


PUSH_BUTTON = """<root BTCPP_format="4" main_tree_to_execute="Pose From Pixel">
  <BehaviorTree ID="Pose From Pixel">
    <Control ID="Sequence">
      <Action ID="GetPointsFromUser" view_name="/wrist_camera/color" point_names="target_pose"
        point_prompts="Click on the button you want to press" pixel_coords="{pixel_coords}" />
      <Action ID="GetPointCloud" topic_name="/wrist_camera/points" message_out="{point_cloud}" />
      <Action ID="GetPoseFromPixelCoords" point_cloud="{point_cloud}" pixel_coords="{pixel_coords}"
        downsample_fraction="0.1" neighbor_radius="0.1" output_poses="{output_poses}" />
      <Decorator ID="ForEach" vector_in="{output_poses}" out="{pose}">
        <Action ID="TransformPose" output_pose="{target_pose}" quaternion_xyzw="0.7071;0.7071;0;0"
          translation_xyz="0;0;0.1" input_pose="{pose}" />
      </Decorator>
    </Control>
  </BehaviorTree>
</root>
"""


def test_push_buttons_call_validates_against_lab_sim(tmp_path: Path) -> None:
    from kinema.config import ObjectiveLibrary, resolve_config
    from kinema.plugins import BehaviorHost
    from kinema.runtime.library_check import file_problem

    resolved = resolve_config("lab_sim")
    host = BehaviorHost.for_config(resolved)
    host.load().raise_for_errors()
    library, factory = ObjectiveLibrary.load(resolved), host.registry.create_factory()
    objective = tmp_path / "pose_from_pixel.xml"
    objective.write_text(PUSH_BUTTON)
    assert file_problem(library, objective, factory) is None
    objective.write_text(PUSH_BUTTON.replace("neighbor_radius=", "neighbour_radius="))
    assert "neighbour_radius" in str(file_problem(library, objective, factory))
