"""How fast simulated time runs against wall time: ``1`` (real time), a factor such as ``4``, or ``max``."""

from __future__ import annotations

import math

from kinema.errors import DriverError

MAX = math.inf


def parse_sim_speed(value: str | float) -> float:
    """Turn ``"1"``, ``"0.5"``, ``"10"`` or ``"max"`` into a factor (``math.inf`` for ``max``).

    Raises:
        DriverError: not a positive number nor ``max``.
    """
    if isinstance(value, int | float):
        factor = float(value)
    else:
        text = value.strip().lower()
        if text in ("max", "inf", "unlimited"):
            return MAX
        try:
            factor = float(text.rstrip("x"))
        except ValueError:
            raise DriverError(
                f"--sim-speed {value!r} is not a speed: use 1 (real time), a factor such as 4, or max"
            ) from None
    if not factor > 0 or math.isnan(factor):
        raise DriverError(f"--sim-speed must be positive (or max), got {value!r}")
    return factor


def format_sim_speed(factor: float) -> str:
    """``max``, ``1x``, ``2.5x``."""
    return "max" if math.isinf(factor) else f"{factor:g}x"
