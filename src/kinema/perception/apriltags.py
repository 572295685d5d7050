"""AprilTag detection and tag images, through the AprilTag 3 C library (``pupil-apriltags``).

:func:`detect_tags` finds tags in a grey image and estimates each tag's pose in the camera's optical
frame (z forward, x right, y down) from the camera intrinsics and the tag's size. The pose follows the
ROS convention for fiducials: origin at the tag's centre, x to the tag's right, y up the tag, z out of
its printed face toward the viewer (AprilTag 3's own frame has y down and z into the tag; the two differ
by a half turn about x). ``tag_size`` is the side of the black square, not counting the white margin.

:func:`tag_image` draws a tag of a family (one pixel a cell, with its white margin) from the library's
own code table, for scenes and printouts.
"""

from __future__ import annotations

import ctypes
import functools
import threading
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinema.errors import PerceptionError
from kinema.perception.intrinsics import CameraIntrinsics

FAMILIES = (
    "tag36h11",
    "tag25h9",
    "tag16h5",
    "tagCircle21h7",
    "tagCircle49h12",
    "tagStandard41h12",
    "tagStandard52h13",
    "tagCustom48h12",
)
# AprilTag 3's tag frame (y down, z into the tag) to the ROS fiducial frame (y up, z out of the tag).
_ROS_IN_APRILTAG = np.diag([1.0, -1.0, -1.0])


def family_name(name: str) -> str:
    """The library's name of a family given as MoveIt Pro writes it (``36h11``) or in full (``tag36h11``).

    Raises:
        PerceptionError: not a family the library knows, naming the valid ones.
    """
    text = name.strip()
    for family in FAMILIES:
        if text in (family, family.removeprefix("tag")):
            return family
    raise PerceptionError(
        f"unknown AprilTag family {name!r}; valid: {', '.join(f.removeprefix('tag') for f in FAMILIES)}"
    )


@dataclass(frozen=True)
class DetectorSettings:
    """The detector's parameters (AprilTag 3's names)."""

    family: str = "tag36h11"
    max_hamming: int = 0
    n_threads: int = 1
    quad_decimate: float = 2.0
    quad_sigma: float = 0.0
    refine_edges: bool = True


@dataclass(frozen=True)
class TagDetection:
    """One tag found in an image.

    Attributes:
        family: the family's full name (``tag36h11``).
        tag_id: the tag's number in its family.
        hamming: bits corrected to decode it.
        decision_margin: how clearly its bits were read (higher is better).
        center: its centre in pixels (u, v).
        corners: 4x2 corner pixels, counter-clockwise from the tag's bottom left.
        camera_T_tag: 4x4 pose of the tag (ROS fiducial frame) in the optical frame.
        pose_error: the pose fit's object-space error (m²).
    """

    family: str
    tag_id: int
    hamming: int
    decision_margin: float
    center: np.ndarray
    corners: np.ndarray
    camera_T_tag: np.ndarray
    pose_error: float


# One C detector per settings, each used by one thread at a time (the library keeps scratch state in it).
_DETECTOR_LOCKS: dict[DetectorSettings, threading.Lock] = {}
_LOCKS_LOCK = threading.Lock()


def _detector_lock(settings: DetectorSettings) -> threading.Lock:
    with _LOCKS_LOCK:
        return _DETECTOR_LOCKS.setdefault(settings, threading.Lock())


def _detector_class() -> type:
    """pupil-apriltags' Detector, destroyed in the order the C library needs.

    Its ``__del__`` frees the tag families before the detector, whose destructor then reads and writes
    those freed families (``apriltag_detector_destroy`` → ``quick_decode_uninit``): heap corruption that
    surfaced as ``malloc(): mismatching next->prev_size`` at the end of a test run. Destroying the
    detector first, then the families, is the library's intended order.
    """
    from pupil_apriltags import Detector

    class OrderedDetector(Detector):  # type: ignore[misc]
        def __del__(self) -> None:
            pointer = getattr(self, "tag_detector_ptr", None)
            if pointer is None:
                return
            self.tag_detector_ptr = None
            self.libc.apriltag_detector_destroy.restype = None
            self.libc.apriltag_detector_destroy(pointer)
            for family, table in self.tag_families.items():
                destroy = getattr(self.libc, f"{family}_destroy")
                destroy.restype = None
                destroy(table)

    return OrderedDetector


@functools.lru_cache(maxsize=8)
def _detector(settings: DetectorSettings) -> Any:
    return _detector_class()(
        families=settings.family,
        nthreads=max(1, int(settings.n_threads)),
        quad_decimate=float(settings.quad_decimate),
        quad_sigma=float(settings.quad_sigma),
        refine_edges=int(bool(settings.refine_edges)),
        decode_sharpening=0.25,
    )


def grey(pixels: np.ndarray) -> np.ndarray:
    """An HxW uint8 grey image of an HxW or HxWx3/4 uint8 image (ITU-R 601 luma)."""
    pixels = np.asarray(pixels)
    if pixels.ndim == 2:
        return np.ascontiguousarray(pixels, dtype=np.uint8)
    rgb = pixels[:, :, :3].astype(np.float32)
    luma = rgb @ np.array([0.299, 0.587, 0.114], dtype=np.float32)
    return np.ascontiguousarray(np.clip(luma + 0.5, 0, 255).astype(np.uint8))


def detect_tags(
    pixels: np.ndarray, intrinsics: CameraIntrinsics, tag_size: float, settings: DetectorSettings
) -> list[TagDetection]:
    """The tags of ``settings.family`` in ``pixels`` (grey or RGB) with their poses in the optical frame.

    Detections with more than ``settings.max_hamming`` corrected bits are dropped.

    Raises:
        PerceptionError: a tag size that is not positive, or an image of another size than the camera's.
    """
    if not tag_size > 0:
        raise PerceptionError(f"tag_size must be positive (metres), got {tag_size}")
    image = grey(pixels)
    if image.shape != (intrinsics.height, intrinsics.width):
        raise PerceptionError(
            f"the image is {image.shape[1]}x{image.shape[0]} but the camera info is "
            f"{intrinsics.width}x{intrinsics.height}"
        )
    with _detector_lock(settings):
        found = _detector(settings).detect(
            image,
            estimate_tag_pose=True,
            camera_params=(intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy),
            tag_size=float(tag_size),
        )
    detections = []
    for tag in found:
        if int(tag.hamming) > int(settings.max_hamming):
            continue
        transform = np.eye(4)
        transform[:3, :3] = np.asarray(tag.pose_R, dtype=float) @ _ROS_IN_APRILTAG
        transform[:3, 3] = np.asarray(tag.pose_t, dtype=float).reshape(3)
        family = tag.tag_family.decode() if isinstance(tag.tag_family, bytes) else str(tag.tag_family)
        detections.append(
            TagDetection(
                family,
                int(tag.tag_id),
                int(tag.hamming),
                float(tag.decision_margin),
                np.asarray(tag.center, dtype=float),
                np.asarray(tag.corners, dtype=float),
                transform,
                float(tag.pose_err),
            )
        )
    return detections


def tag_image(family: str, tag_id: int) -> np.ndarray:
    """The tag ``tag_id`` of ``family`` as a uint8 image, one pixel a cell (0 black, 255 white).

    The image includes the tag's white margin: 10x10 for tag36h11, whose black square is the middle 8x8.

    Raises:
        PerceptionError: an unknown family, or an id the family does not have.
    """
    from pupil_apriltags.bindings import _ApriltagFamily

    name = family_name(family)
    library = _detector(DetectorSettings(name)).libc  # the cached detector's library: none is destroyed
    create = getattr(library, f"{name}_create")
    create.restype = ctypes.POINTER(_ApriltagFamily)
    destroy = getattr(library, f"{name}_destroy")
    destroy.restype = None
    pointer = create()
    try:
        table = pointer.contents
        if not 0 <= tag_id < int(table.ncodes):
            raise PerceptionError(f"{name} has tags 0..{int(table.ncodes) - 1}, not {tag_id}")
        size = int(table.total_width)
        image = np.zeros((size, size), dtype=np.uint8)
        if not table.reversed_border:
            image[0, :] = image[-1, :] = image[:, 0] = image[:, -1] = 255
        start = (size - int(table.width_at_border)) // 2
        code, bits = int(table.codes[tag_id]), int(table.nbits)
        for i in range(bits):
            if (code >> (bits - 1 - i)) & 1:
                image[int(table.bit_y[i]) + start, int(table.bit_x[i]) + start] = 255
    finally:
        destroy(pointer)  # never added to a detector, so nothing else refers to it
    return image
