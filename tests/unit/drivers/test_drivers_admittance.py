"""The admittance law of the joint trajectory admittance controller, on a frame whose Jacobian is the
identity (six joints that move the control frame's six axes directly)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from kinema.drivers.mujoco.admittance import Admittance, AdmittanceError, AdmittanceParameters
from kinema.transport import from_dict

PARAMETERS = "moveit_pro_controllers_msgs/msg/AdmittanceParameters"
DT = 0.002


class _IdentityFrame:
    """A control frame at the world origin whose six axes are six joints."""

    def pose(self, data: Any) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros(3), np.eye(3)

    def jacobian(self, model: Any, data: Any, dofs: np.ndarray) -> np.ndarray:
        return np.eye(6)


# Admittance takes a ControlFrame; this stand-in has the two methods it calls.
FRAME: Any = _IdentityFrame()


def _parameters(mass: float, stiffness: float, ratio: float, axes: str = "x y z rx ry rz") -> Any:
    selected = axes.split()
    return AdmittanceParameters(
        selected=np.array([a in selected for a in ("x", "y", "z", "rx", "ry", "rz")]),
        mass=np.full(6, mass),
        stiffness=np.full(6, stiffness),
        damping_ratio=np.full(6, ratio),
    )


def _run(parameters: AdmittanceParameters, wrench: np.ndarray, seconds: float, dt: float = DT) -> Admittance:
    admittance = Admittance(parameters, FRAME, np.arange(6), np.full(6, -10.0), np.full(6, 10.0), 0.0)
    for _ in range(round(seconds / dt)):
        admittance.step(None, None, wrench, np.zeros(6), dt)
    return admittance


@pytest.mark.parametrize(
    ("mass", "stiffness", "ratio", "force", "expected"),
    [
        (1.0, 100.0, 1.0, 10.0, 0.1),  # critically damped: settles at F / K
        (1.0, 400.0, 1.0, 10.0, 0.025),
        (0.001, 180.0, 100.0, 9.0, 0.05),  # a tiny mass under heavy damping stays stable (implicit Euler)
        (4.0, 40.0, 0.5, 20.0, 0.5),  # underdamped: rings, then settles
    ],
)
def test_the_offset_settles_at_force_over_stiffness(
    mass: float, stiffness: float, ratio: float, force: float, expected: float
) -> None:
    wrench = np.array([force, 0.0, 0.0, 0.0, 0.0, 0.0])
    admittance = _run(_parameters(mass, stiffness, ratio), wrench, 20.0, dt=0.01)
    assert admittance.x[0] == pytest.approx(expected, rel=1e-3)
    assert admittance.joint_offset[0] == pytest.approx(expected, rel=1e-3)
    assert np.abs(admittance.x[1:]).max() < 1e-9


def test_heavy_damping_slows_the_give_to_its_time_constant() -> None:
    # D = 2 * 100 * sqrt(0.1 * 180) = 848.5 N s/m: after one time constant D / K the offset is 63 % of F / K.
    damping = 2 * 100 * np.sqrt(0.1 * 180.0)
    admittance = _run(_parameters(0.1, 180.0, 100.0), np.array([0, 0, 9.0, 0, 0, 0]), damping / 180.0)
    assert admittance.x[2] == pytest.approx(0.05 * (1 - np.exp(-1)), rel=0.01)


def test_unselected_axes_stay_rigid() -> None:
    wrench = np.array([10.0, 10.0, 10.0, 1.0, 1.0, 1.0])
    admittance = _run(_parameters(1.0, 100.0, 1.0, axes="z"), wrench, 5.0, dt=0.01)
    assert admittance.x[2] == pytest.approx(0.1, rel=1e-2)
    assert np.abs(np.delete(admittance.joint_offset, 2)).max() < 1e-12


def test_joint_limits_bound_the_offset() -> None:
    admittance = Admittance(
        _parameters(1.0, 10.0, 1.0),
        FRAME,
        np.arange(6),
        np.full(6, -0.05),
        np.full(6, 0.05),
        0.0,
    )
    for _ in range(500):
        admittance.step(None, None, np.array([10.0, 0, 0, 0, 0, 0]), np.zeros(6), 0.01)
    assert admittance.joint_offset[0] == pytest.approx(0.05)


def test_a_message_without_selected_axes_is_no_admittance_and_bad_values_are_named() -> None:
    assert AdmittanceParameters.from_message(from_dict(PARAMETERS, {})) is None
    message = from_dict(
        PARAMETERS,
        {
            "selected_axes": {"x": True, "rz": True},
            "mass_position": {"x": 0.0},
            "mass_rotation": {"z": 1.0},
            "stiffness_rotation": {"z": -1.0},
        },
    )
    with pytest.raises(AdmittanceError) as error:
        AdmittanceParameters.from_message(message)
    assert "mass x = 0 (must be positive)" in str(error.value)
    assert "stiffness rz = -1 (must not be negative)" in str(error.value)
