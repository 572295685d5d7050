"""UI: behaviors that show things to the user (toasts, markers in ``kinema view``, TUI notices)."""

from __future__ import annotations

from .log_message import LogMessage
from .visualize_pose import VisualizePose

BEHAVIORS = (LogMessage, VisualizePose)
