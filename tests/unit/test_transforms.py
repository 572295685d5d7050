"""kinema.transforms: the one home of pose, quaternion, matrix and twist conversions."""

from __future__ import annotations

import math
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from kinema import transforms
from kinema.errors import KinemaError

REPO = Path(__file__).resolve().parents[2]
S = math.sqrt(0.5)

# (quaternion x, y, z, w, the rotation matrix it means)
ROTATIONS = [
    ((0.0, 0.0, 0.0, 1.0), np.eye(3)),
    ((0.0, 0.0, S, S), np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])),  # +90 deg about z
    ((S, 0.0, 0.0, S), np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])),  # +90 deg about x
    ((0.0, 1.0, 0.0, 0.0), np.diag([-1.0, 1.0, -1.0])),  # 180 deg about y
    ((0.0, 0.0, 2.0, 2.0), np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])),  # not unit: normalised
    ((0.0, 0.0, 0.0, 0.0), np.eye(3)),  # all zero: an unset orientation, the identity
    ((0.0, 0.0, 0.0, 1e-12), np.eye(3)),  # below ZERO_NORM counts as zero
]


@pytest.mark.parametrize(("quaternion", "matrix"), ROTATIONS)
def test_rotation_matrix_of_a_quaternion(quaternion: tuple[float, ...], matrix: np.ndarray) -> None:
    np.testing.assert_allclose(transforms.rotation_matrix(quaternion), matrix, atol=1e-12)


@pytest.mark.parametrize(
    ("value", "says"),
    [
        ((0.0, 0.0, math.nan, 1.0), "NaN or infinite"),
        ((0.0, math.inf, 0.0, 1.0), "NaN or infinite"),
        ((0.0, 0.0, 1.0), "got 3"),
        ("not numbers", "4 numbers"),
    ],
)
def test_input_that_is_no_rotation_raises_one_error(value: object, says: str) -> None:
    with pytest.raises(transforms.TransformError, match=says) as caught:
        transforms.unit_quaternion(value)
    assert isinstance(caught.value, KinemaError) and isinstance(caught.value, ValueError)


def test_zero_quaternion_is_the_identity_everywhere_it_is_read() -> None:
    zero = {"position": {"x": 1.0, "y": 2.0, "z": 3.0}, "orientation": {"x": 0, "y": 0, "z": 0, "w": 0}}
    expected = np.eye(4)
    expected[:3, 3] = [1, 2, 3]
    np.testing.assert_allclose(transforms.pose_from_message(zero), expected)
    np.testing.assert_allclose(transforms.pose_matrix([1, 2, 3], [0, 0, 0, 0]), expected)
    np.testing.assert_allclose(transforms.unit_quaternion([0, 0, 0, 0]), [0, 0, 0, 1])
    assert transforms.is_zero_quaternion([0, 0, 0, 0]) and not transforms.is_zero_quaternion([0, 0, 0, 1])


def test_pose_round_trips_through_matrix_message_and_dict() -> None:
    rng = np.random.default_rng(7)
    for _ in range(50):
        q = rng.normal(size=4)
        position = rng.normal(size=3)
        pose = transforms.pose_matrix(position, q)
        as_dict = transforms.pose_dict(pose)
        message = SimpleNamespace(
            position=SimpleNamespace(**as_dict["position"]),
            orientation=SimpleNamespace(**as_dict["orientation"]),
        )
        np.testing.assert_allclose(transforms.pose_from_message(message), pose, atol=1e-12)
        np.testing.assert_allclose(transforms.pose_from_message(as_dict), pose, atol=1e-12)
        back_position, back_q = transforms.pose_parts(pose)
        np.testing.assert_allclose(back_position, position)
        unit = q / np.linalg.norm(q)
        assert min(np.linalg.norm(back_q - unit), np.linalg.norm(back_q + unit)) < 1e-9
        np.testing.assert_allclose(transforms.invert(pose) @ pose, np.eye(4), atol=1e-12)


def test_mujoco_order_and_euler_angles() -> None:
    np.testing.assert_allclose(transforms.quaternion_from_wxyz([S, 0, 0, S]), [0, 0, S, S])
    np.testing.assert_allclose(
        transforms.rotation_from_euler([0, 0, math.pi / 2]),
        transforms.rotation_matrix([0, 0, S, S]),
        atol=1e-12,
    )
    np.testing.assert_allclose(
        transforms.rotation_from_rotvec([math.pi / 2, 0, 0]),
        transforms.rotation_matrix([S, 0, 0, S]),
        atol=1e-12,
    )


def test_slerp_takes_the_shorter_way_and_angle_between_ignores_the_sign() -> None:
    start, end = np.array([0, 0, 0, 1.0]), np.array([0, 0, -S, -S])  # +90 deg about z, written negated
    middle = transforms.slerp(start, end, 0.5)
    eighth = np.array([0.0, 0.0, math.sin(math.pi / 8), math.cos(math.pi / 8)])  # +45 deg about z
    assert min(np.linalg.norm(middle - eighth), np.linalg.norm(middle + eighth)) < 1e-9
    assert transforms.angle_between(start, end) == pytest.approx(math.pi / 2)
    np.testing.assert_allclose(transforms.slerp(start, end, 0.0), start, atol=1e-12)


def test_rotate_twist_turns_both_halves() -> None:
    about_z = transforms.rotation_matrix([0, 0, S, S])
    twist = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0]  # +x linear, +y angular
    np.testing.assert_allclose(transforms.rotate_twist(about_z, twist), [0, 1, 0, -1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(
        transforms.rotate_twist(about_z.T, transforms.rotate_twist(about_z, twist)), twist, atol=1e-12
    )


def test_no_other_module_builds_rotations_itself() -> None:
    """Every rotation goes through kinema.transforms: no scipy Rotation and no hand formula elsewhere."""
    hand_formula = re.compile(r"1 - 2 \* \(\w \* \w \+ \w \* \w\)")
    offenders = []
    for root in (REPO / "src" / "kinema", REPO / "plugins"):
        for path in root.rglob("*.py"):
            if path.name == "transforms.py" and path.parent.name == "kinema":
                continue
            text = path.read_text(encoding="utf-8")
            if "scipy.spatial.transform" in text or hand_formula.search(text):
                offenders.append(str(path.relative_to(REPO)))
    assert offenders == []
