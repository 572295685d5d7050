"""Waiting: behaviors that pass time on the tree's clock."""

from __future__ import annotations

from .wait_for_duration import WaitForDuration

BEHAVIORS = (WaitForDuration,)
