"""AprilTag detection through the AprilTag 3 library, on tags drawn by a pinhole camera at known poses."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from kinema.errors import PerceptionError
from kinema.perception.apriltags import DetectorSettings, detect_tags, family_name, tag_image
from kinema.perception.intrinsics import CameraIntrinsics

CAMERA = CameraIntrinsics.from_fovy(640, 480, 58.0)
TAG_SIZE = 0.0288  # lab_sim objectives' object tags: the black square's side


def draw_tag(
    tag: np.ndarray, tag_size: float, camera_T_tag: np.ndarray, camera: CameraIntrinsics, samples: int = 3
) -> np.ndarray:
    """A grey image of ``tag`` (one pixel a cell, margin included) on a mid-grey background, seen by
    ``camera`` with the tag's ROS frame (x right, y up, z out of the face) at ``camera_T_tag``."""
    cells = tag.shape[0]
    width = tag_size * cells / (cells - 2)  # the margin is one cell on each side
    rotation, origin = camera_T_tag[:3, :3], camera_T_tag[:3, 3]
    normal = rotation[:, 2]
    offsets = (np.arange(samples) + 0.5) / samples - 0.5
    total = np.zeros((camera.height, camera.width))
    v, u = np.mgrid[0 : camera.height, 0 : camera.width].astype(float)
    for du in offsets:
        for dv in offsets:
            rays = np.stack(
                [(u + du - camera.cx) / camera.fx, (v + dv - camera.cy) / camera.fy, np.ones_like(u)], -1
            )
            depth = (origin @ normal) / (rays @ normal)
            local = (rays * depth[..., None] - origin) @ rotation  # tag-frame coordinates
            col = np.floor((local[..., 0] + width / 2) / width * cells).astype(int)
            row = np.floor((width / 2 - local[..., 1]) / width * cells).astype(int)
            inside = (col >= 0) & (col < cells) & (row >= 0) & (row < cells) & (depth > 0)
            shade = np.full(u.shape, 128.0)
            shade[inside] = tag[row[inside], col[inside]]
            total += shade
    return (total / samples**2).astype(np.uint8)


def pose(xyz: tuple[float, float, float], rotvec_degrees: tuple[float, float, float]) -> np.ndarray:
    transform = np.eye(4)
    # Face the camera: the tag's z points back at it, then the given extra rotation.
    facing = Rotation.from_euler("x", 180, degrees=True)
    transform[:3, :3] = (facing * Rotation.from_rotvec(rotvec_degrees, degrees=True)).as_matrix()
    transform[:3, 3] = xyz
    return transform


def angle_between(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.degrees(Rotation.from_matrix(a[:3, :3].T @ b[:3, :3]).magnitude()))


def test_tag_image_has_the_family_layout_and_differs_by_id() -> None:
    first, second = tag_image("36h11", 0), tag_image("tag36h11", 1)
    assert first.shape == (10, 10) and set(np.unique(first)) == {0, 255}
    assert (first[0] == 255).all() and (first[1, 1:-1] == 0).all(), "white margin, then the black border"
    assert not np.array_equal(first, second)
    with pytest.raises(PerceptionError, match=r"0\.\.586"):
        tag_image("36h11", 587)


@pytest.mark.parametrize(
    ("xyz", "rotvec"),
    [((0.0, 0.0, 0.25), (0.0, 0.0, 0.0)), ((0.03, -0.02, 0.3), (15.0, -10.0, 40.0))],
)
def test_a_drawn_tag_is_found_at_its_pose(xyz: tuple[float, float, float], rotvec: tuple) -> None:
    truth = pose(xyz, rotvec)
    image = draw_tag(tag_image("36h11", 7), TAG_SIZE, truth, CAMERA)
    found = detect_tags(image, CAMERA, TAG_SIZE, DetectorSettings())
    assert [tag.tag_id for tag in found] == [7], found
    tag = found[0]
    assert tag.family == "tag36h11" and tag.hamming == 0
    error = np.linalg.norm(tag.camera_T_tag[:3, 3] - truth[:3, 3])
    assert error < 0.003, f"position off by {error * 1000:.1f} mm: {tag.camera_T_tag[:3, 3]} vs {xyz}"
    assert angle_between(tag.camera_T_tag, truth) < 3.0
    # The ROS fiducial frame: z out of the face, back toward the camera.
    assert tag.camera_T_tag[:3, 2] @ tag.camera_T_tag[:3, 3] < 0


def test_other_families_and_rgb_images_are_taken() -> None:
    truth = pose((0.0, 0.01, 0.3), (0.0, 0.0, 20.0))
    grey_image = draw_tag(tag_image("25h9", 3), 0.04, truth, CAMERA)
    rgb = np.repeat(grey_image[:, :, None], 3, axis=2)
    assert [t.tag_id for t in detect_tags(rgb, CAMERA, 0.04, DetectorSettings("tag25h9"))] == [3]
    assert detect_tags(rgb, CAMERA, 0.04, DetectorSettings("tag36h11")) == [], "another family's tag"


def test_bad_settings_name_what_is_valid() -> None:
    with pytest.raises(PerceptionError, match="valid: 36h11"):
        family_name("36h12")
    image = np.zeros((480, 640), dtype=np.uint8)
    with pytest.raises(PerceptionError, match="tag_size must be positive"):
        detect_tags(image, CAMERA, 0.0, DetectorSettings())
    with pytest.raises(PerceptionError, match="320x240 but the camera info is 640x480"):
        detect_tags(image[:240, :320], CAMERA, TAG_SIZE, DetectorSettings())


def test_detections_from_several_threads_at_once_are_each_right() -> None:
    """Behaviors detect on worker threads; the library's detector keeps scratch state, so calls queue."""
    from concurrent.futures import ThreadPoolExecutor

    images = {
        tag_id: draw_tag(tag_image("36h11", tag_id), TAG_SIZE, pose((0.0, 0.0, 0.25), (0, 0, 10)), CAMERA)
        for tag_id in (2, 4, 6, 8)
    }

    def ids(tag_id: int) -> list[int]:
        return [t.tag_id for t in detect_tags(images[tag_id], CAMERA, TAG_SIZE, DetectorSettings())]

    asked = list(images) * 3
    with ThreadPoolExecutor(4) as pool:
        found = list(pool.map(ids, asked))
    assert found == [[tag_id] for tag_id in asked]


def test_a_detector_is_destroyed_before_its_tag_families() -> None:
    """The C detector's destructor still reads its families: freeing them first corrupts the heap."""
    from kinema.perception.apriltags import _detector_class

    calls: list[str] = []

    class Library:
        def __getattr__(self, name: str) -> object:
            class Call:
                restype = None

                def __call__(self, *args: object) -> None:
                    calls.append(name)

            value = Call()
            setattr(self, name, value)
            return value

    detector = object.__new__(_detector_class())
    detector.libc, detector.tag_detector_ptr = Library(), object()
    detector.tag_families = {"tag36h11": object(), "tag25h9": object()}
    detector.__del__()
    assert calls == ["apriltag_detector_destroy", "tag36h11_destroy", "tag25h9_destroy"]
    detector.__del__()  # a second call does nothing
    assert len(calls) == 3
