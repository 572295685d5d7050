"""GenerateCoveragePath, GetContourFromPointCloudSlice and CalibrateCameraPose: the raster, the outline and
the camera pose they compute, checked against geometry known in advance."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import publish_repeatedly, tick_behavior
from kinema.transforms import pose_dict, pose_from_message, rotation_from_euler
from kinema.transport import from_dict

ARM = [
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
]
HOME = [0.0, 0.0, -2.0, 2.0, -1.5708, -1.5708, 0.0]


def _pose(frame: str, matrix: np.ndarray) -> Any:
    return from_dict(
        "geometry_msgs/msg/PoseStamped", {"header": {"frame_id": frame}, "pose": pose_dict(matrix)}
    )


def _matrix(xyz: tuple[float, ...], rpy: tuple[float, ...] = (0, 0, 0)) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, :3] = rotation_from_euler(rpy)
    matrix[:3, 3] = xyz
    return matrix


@pytest.fixture
def at_home(context: BehaviorContext) -> Iterator[None]:
    state = {"name": [*ARM, "robotiq_85_left_knuckle_joint"], "position": [*HOME, 0.0]}
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        yield


# -- GenerateCoveragePath ---------------------------------------------------------------------------------


def test_generate_coverage_path_sweeps_the_rectangle_back_and_forth(
    behavior: Any, context: BehaviorContext
) -> None:
    corner = _matrix((0.3, -0.2, 1.0), (0.0, np.pi / 2, 0.0))
    run = tick_behavior(
        behavior("GenerateCoveragePath"),
        {
            "bottom_right_corner": _pose("grasp_link", corner),
            "width": 0.5,
            "height": 0.25,
            "stride_distance": 0.1,
        },
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    poses = run.outputs["vector_of_poses"]
    assert {p.header.frame_id for p in poses} == {"grasp_link"}
    # each pose in the corner's own frame: passes at 0, 0.1, 0.2 and the top edge 0.25, alternating
    local = [np.linalg.inv(corner) @ pose_from_message(p.pose) for p in poses]
    np.testing.assert_allclose(
        [m[:3, 3] for m in local],
        [
            [0, 0, 0], [-0.5, 0, 0], [-0.5, 0.1, 0], [0, 0.1, 0],
            [0, 0.2, 0], [-0.5, 0.2, 0], [-0.5, 0.25, 0], [0, 0.25, 0],
        ],
        atol=1e-9,
    )  # fmt: skip
    for m in local:
        np.testing.assert_allclose(m[:3, :3], np.eye(3), atol=1e-9)  # the corner's orientation


@pytest.mark.parametrize(
    ("sizes", "message"),
    [
        ({"width": 0.0}, "width must be > 0"),
        ({"stride_distance": -0.1}, "stride_distance must be > 0"),
        ({"height": 100.0, "stride_distance": 0.001}, "more than 10000"),
    ],
)
def test_generate_coverage_path_refuses_sizes_that_make_no_raster(
    behavior: Any, context: BehaviorContext, sizes: dict[str, float], message: str
) -> None:
    run = tick_behavior(
        behavior("GenerateCoveragePath"),
        {"bottom_right_corner": _pose("world", np.eye(4)), **sizes},
        context=context,
    )
    assert run.status == NodeStatus.FAILURE and message in run.toasts[-1]


# -- GetContourFromPointCloudSlice ------------------------------------------------------------------------


def _cloud(points: np.ndarray, frame: str = "world") -> Any:
    from kinema.interfaces import load_interfaces
    from kinema.perception import PointCloud
    from kinema.perception.ros_messages import to_point_cloud2

    cloud = PointCloud(np.asarray(points, dtype=float), frame_id=frame)
    return to_point_cloud2(cloud, load_interfaces().typestore.types)


def _square_prism(centre: tuple[float, float], half: float, rng: np.random.Generator) -> np.ndarray:
    """Points on the four side faces of a square prism (a post 1 m tall), as a camera going round sees it."""
    t = rng.uniform(-half, half, 4000)
    z = rng.uniform(0.0, 1.0, 4000)
    side = rng.integers(0, 4, 4000)
    x = np.where(side == 0, half, np.where(side == 1, -half, t))
    y = np.where(side == 2, half, np.where(side == 3, -half, t))
    return np.column_stack([x + centre[0], y + centre[1], z])


@pytest.fixture
def contour(behavior: Any, context: BehaviorContext) -> Any:
    def run(points: np.ndarray, plane: np.ndarray, **ports: Any) -> Any:
        return tick_behavior(
            behavior("GetContourFromPointCloudSlice"),
            {"input_cloud": _cloud(points), "slice_plane": _pose("world", plane), **ports},
            context=context,
        )

    return run


def test_the_outline_of_a_post_is_its_square_with_poses_facing_it(contour: Any) -> None:
    points = _square_prism((1.0, 0.0), 0.2, np.random.default_rng(1))
    run = contour(points, _matrix((1.0, 0.0, 0.5)), slice_distance_from_plane=0.05, max_pose_spacing=0.1)
    assert run.status == NodeStatus.SUCCESS, run.toasts
    poses = [pose_from_message(p.pose) for p in run.outputs["contour_path"]]
    positions = np.array([p[:3, 3] for p in poses])
    np.testing.assert_allclose(positions[:, 2], 0.5, atol=1e-9)  # on the plane
    edge = np.maximum(np.abs(positions[:, 0] - 1.0), np.abs(positions[:, 1]))
    assert np.all(np.abs(edge - 0.2) < 0.01)  # on the square's sides
    assert np.all(np.linalg.norm(np.diff(positions, axis=0), axis=1) <= 0.1 + 1e-9)
    np.testing.assert_allclose(positions[0], positions[-1])  # the whole outline, closed
    for pose in poses[1:-1]:  # z toward the post's axis
        inward = np.array([1.0, 0.0, 0.5]) - pose[:3, 3]
        assert pose[:3, 2] @ inward > 0


def test_a_cropped_outline_keeps_the_angles_asked_for_in_order(contour: Any) -> None:
    points = _square_prism((1.0, 0.0), 0.2, np.random.default_rng(2))
    run = contour(
        points,
        _matrix((1.0, 0.0, 0.5)),
        slice_distance_from_plane=0.05,
        contour_crop_angle_start=np.pi / 2,
        contour_crop_angle_span=np.pi,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    positions = np.array([pose_from_message(p.pose)[:3, 3] for p in run.outputs["contour_path"]])
    assert np.all(positions[:, 0] <= 1.0 + 1e-6)  # the half facing -x only
    assert positions[0][1] > 0 > positions[-1][1]  # from +y round the -x side to -y


def test_a_concave_hull_follows_a_notch_the_convex_hull_bridges(contour: Any) -> None:
    grid = np.array([(x, y) for x in np.arange(0, 1.001, 0.02) for y in np.arange(0, 1.001, 0.02)])
    ell = grid[(grid[:, 0] <= 0.4001) | (grid[:, 1] <= 0.4001)]  # an L: the square without its top right
    points = np.column_stack([ell, np.zeros(len(ell))])
    plane = _matrix((0.5, 0.5, 0.0))
    convex = contour(points, plane, slice_distance_from_plane=0.01, max_pose_spacing=0.05)
    concave = contour(points, plane, slice_distance_from_plane=0.01, max_pose_spacing=0.05, hull_alpha=0.05)
    assert convex.status == NodeStatus.SUCCESS and concave.status == NodeStatus.SUCCESS, concave.toasts

    def reaches_notch(run: Any) -> bool:
        positions = np.array([pose_from_message(p.pose)[:3, 3] for p in run.outputs["contour_path"]])
        return bool(np.min(np.linalg.norm(positions[:, :2] - [0.4, 0.4], axis=1)) < 0.05)

    assert reaches_notch(concave) and not reaches_notch(convex)


def test_a_slice_that_misses_the_cloud_says_how_many_points_it_found(contour: Any) -> None:
    points = _square_prism((1.0, 0.0), 0.2, np.random.default_rng(3))
    run = contour(points, _matrix((1.0, 0.0, 3.0)), slice_distance_from_plane=0.05)
    assert run.status == NodeStatus.FAILURE and "0 point(s) of the cloud lie within 0.05 m" in run.toasts[-1]


# -- CalibrateCameraPose ----------------------------------------------------------------------------------

# the tags on the tool, in the tool frame's convention: centroid at the origin, left to right along x
TAGS = {"left": (-0.05, 0.03, 0.0), "right": (0.05, 0.03, 0.0), "bottom": (0.0, -0.06, 0.0)}


def test_the_camera_is_found_where_it_sees_the_tool_from(
    behavior: Any, context: BehaviorContext, at_home: None, lab_sim_model: Any
) -> None:
    from kinema.motion import fk

    q = lab_sim_model.configuration(dict(zip(ARM, HOME, strict=True)))
    base_T_tool = np.linalg.inv(fk(lab_sim_model, q, "base_link")) @ fk(lab_sim_model, q, "grasp_link")
    # the real camera: 3 cm and 2 degrees off where the description has it
    described = np.linalg.inv(fk(lab_sim_model, q, "base_link")) @ fk(
        lab_sim_model, q, "scene_camera_optical_frame"
    )
    real = described @ _matrix((0.03, -0.01, 0.02), (0.0, 0.035, 0.0))
    seen = {
        f"{side}_tag_pose": _pose(
            "scene_camera_optical_frame",
            np.linalg.inv(real) @ base_T_tool @ _matrix(xyz, (0.3, 0.0, 0.0)),  # a tag's turn is ignored
        )
        for side, xyz in TAGS.items()
    }
    run = tick_behavior(
        behavior("CalibrateCameraPose"),
        {
            "base_link": "base_link",
            "calibration_tool_frame": "grasp_link",
            "camera_optical_frame": "scene_camera_optical_frame",
            **seen,
        },
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    computed = run.outputs["computed_pose"]
    assert computed.header.frame_id == "base_link"
    np.testing.assert_allclose(pose_from_message(computed.pose), real, atol=1e-6)


def test_tags_on_one_line_define_no_tool_frame(
    behavior: Any, context: BehaviorContext, at_home: None
) -> None:
    seen = {
        f"{side}_tag_pose": _pose("scene_camera_optical_frame", _matrix((x, 0.0, 1.0)))
        for side, x in (("left", -0.1), ("right", 0.1), ("bottom", 0.0))
    }
    run = tick_behavior(
        behavior("CalibrateCameraPose"),
        {
            "base_link": "base_link",
            "calibration_tool_frame": "grasp_link",
            "camera_optical_frame": "scene_camera_optical_frame",
            **seen,
        },
        context=context,
    )
    assert run.status == NodeStatus.FAILURE and "on the line through the left and right" in run.toasts[-1]
