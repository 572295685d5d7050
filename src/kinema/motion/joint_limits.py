"""Joint limits: positions from the URDF; velocities and accelerations from MoveIt's joint_limits.yaml."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from kinema.config.yamlsource import AngleLoader
from kinema.errors import MotionError, SourceLocation


@dataclass(frozen=True)
class JointLimits:
    """Limits of one joint in SI units (m or rad; per s, per s²).

    ``max_velocity``/``max_acceleration`` are ``inf`` when neither file bounds them.
    """

    lower: float
    upper: float
    max_velocity: float
    max_acceleration: float


@dataclass(frozen=True)
class LimitsFile:
    """The parsed contents of a joint_limits.yaml file."""

    joints: dict[str, dict[str, Any]]
    default_velocity_scaling_factor: float = 1.0
    default_acceleration_scaling_factor: float = 1.0


_KNOWN_KEYS = {
    "has_position_limits",
    "min_position",
    "max_position",
    "has_velocity_limits",
    "max_velocity",
    "has_acceleration_limits",
    "max_acceleration",
    "has_jerk_limits",
    "max_jerk",
    "has_effort_limits",
    "max_effort",
    "has_deceleration_limits",
    "max_deceleration",
}


def parse_joint_limits(path: str | Path) -> LimitsFile:
    """Read MoveIt's ``joint_limits.yaml`` (``joint_limits: {joint: {max_velocity: ..., ...}}``).

    Raises:
        MotionError: unreadable file, bad YAML, or a non-numeric limit (with the file name).
    """
    path = Path(path)
    try:
        data = yaml.load(path.read_text(), Loader=AngleLoader) or {}
    except OSError as exc:
        raise MotionError(f"cannot read joint limits {path}: {exc}") from exc
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = mark.line + 1 if mark is not None else 0
        raise MotionError(
            f"joint limits file is not valid YAML: {exc}", location=SourceLocation(str(path), line)
        ) from exc
    joints = data.get("joint_limits") or {}
    if not isinstance(joints, dict):
        raise MotionError("'joint_limits' must map joint names to limits", location=SourceLocation(str(path)))
    for name, entry in joints.items():
        if not isinstance(entry, dict):
            raise MotionError(
                f"limits of joint {name!r} must be a mapping", location=SourceLocation(str(path))
            )
        for key, value in entry.items():
            if key in _KNOWN_KEYS and not key.startswith("has_") and not isinstance(value, int | float):
                raise MotionError(
                    f"{name}.{key} must be a number, got {value!r}", location=SourceLocation(str(path))
                )
    return LimitsFile(
        joints=joints,
        default_velocity_scaling_factor=float(data.get("default_velocity_scaling_factor", 1.0)),
        default_acceleration_scaling_factor=float(data.get("default_acceleration_scaling_factor", 1.0)),
    )


def merge_limits(
    name: str, lower: float, upper: float, urdf_velocity: float, overrides: dict[str, Any] | None
) -> JointLimits:
    """Combine the URDF limits of joint ``name`` with its joint_limits.yaml entry (YAML wins where set)."""
    entry = overrides or {}
    if entry.get("has_position_limits"):
        lower = float(entry.get("min_position", lower))
        upper = float(entry.get("max_position", upper))
    velocity = urdf_velocity if urdf_velocity > 0 else float("inf")
    if entry.get("has_velocity_limits"):
        velocity = float(entry["max_velocity"])
    acceleration = float(entry["max_acceleration"]) if entry.get("has_acceleration_limits") else float("inf")
    return JointLimits(lower=lower, upper=upper, max_velocity=velocity, max_acceleration=acceleration)
