"""--sim-speed values."""

from __future__ import annotations

import math

import pytest

from kinema.drivers.mujoco.sim_speed import format_sim_speed, parse_sim_speed
from kinema.errors import DriverError


@pytest.mark.parametrize(
    ("text", "factor"),
    [("1", 1.0), ("0.5", 0.5), ("10", 10.0), ("4x", 4.0), ("max", math.inf), ("MAX", math.inf), (2, 2.0)],
)
def test_valid_speeds(text: str | float, factor: float) -> None:
    assert parse_sim_speed(text) == factor


@pytest.mark.parametrize("text", ["0", "-1", "fast", "", "nan"])
def test_invalid_speeds_say_what_is_accepted(text: str) -> None:
    with pytest.raises(DriverError, match="sim-speed"):
        parse_sim_speed(text)


def test_format() -> None:
    assert [format_sim_speed(f) for f in (math.inf, 1.0, 2.5)] == ["max", "1x", "2.5x"]
