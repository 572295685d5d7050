"""Waiting: behaviors that pass or measure time on the tree's clock."""

from __future__ import annotations

from .stopwatch import StopwatchBegin, StopwatchEnd
from .wait_for_duration import WaitForDuration

BEHAVIORS = (WaitForDuration, StopwatchBegin, StopwatchEnd)
