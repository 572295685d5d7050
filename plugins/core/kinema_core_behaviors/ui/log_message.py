"""LogMessage: show a message in the UI log (info, warning or error), with blackboard values in it."""

from __future__ import annotations

import re
from typing import Any

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port

LEVELS = ("info", "warn", "error")
# {key} inside a longer message; a whole "{key}" is a blackboard pointer, read by the port itself.
_PLACEHOLDER = re.compile(r"\{(@?[A-Za-z_][\w.@]*)\}")
MAX_VALUE_CHARS = 400


class LogMessage(SyncBehavior):
    """Publishes ``message`` at ``log_level`` (``info``, ``warn`` or ``error``) and succeeds.

    A ``{key}`` inside the text (``message="picked at {grasp_pose}"``) is replaced by the blackboard value
    of ``key``, whatever its type, in readable form: messages as their fields (``{pose: {position: {x:
    0.5, ...}}}``), vectors as lists, numbers and strings as they are; a key that is not set shows as
    ``{key}: (not set)``. A message that is only ``{key}`` is MoveIt Pro's blackboard pointer to a string.

    An ``error`` message is shown as a failure toast but does not fail the behavior; follow it with
    ``AlwaysFailure`` for that.
    """

    subcategory = "User Interface"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("message", str, "", "The text to show; {key} inside it shows a blackboard value."),
            input_port("log_level", str, "info", "info, warn or error."),
        ]

    def tick(self) -> NodeStatus:
        message = str(self.get_input_or("message", ""))
        if "{" in message:
            message = _PLACEHOLDER.sub(self._value_of, message)
        level = str(self.get_input("log_level")).strip().lower()
        if level in ("warning",):
            level = "warn"
        if level not in LEVELS:
            self.logger.publish_failure(f"LogMessage: log_level must be info, warn or error, got {level!r}")
            return NodeStatus.FAILURE
        if level == "info":
            self.logger.publish_info(message)
        elif level == "warn":
            self.logger.publish_warn(message)
        else:
            self.logger.publish_failure(message)
        return NodeStatus.SUCCESS

    def _value_of(self, found: re.Match[str]) -> str:
        entry = self.config.blackboard.get_entry(found.group(1))
        if entry is None or entry.value is None:
            return f"{found.group(0)}: (not set)"
        return readable(entry.value)


def readable(value: Any) -> str:
    """``value`` as one line a person reads: YAML flow style, messages as their fields, cut when long."""
    import yaml

    try:
        text = yaml.safe_dump(_plain(value), default_flow_style=True, width=1 << 30, sort_keys=False)
        text = text.strip().removesuffix("...").strip()
    except yaml.YAMLError:
        text = repr(value)
    return text if len(text) <= MAX_VALUE_CHARS else text[: MAX_VALUE_CHARS - 1] + "…"


def _plain(value: Any) -> Any:
    """Plain Python data YAML can write: messages as dicts, numpy as lists and numbers."""
    if value is None or isinstance(value, str | bool | int | float):
        return value
    if hasattr(value, "__msgtype__"):
        from kinema.transport.messages import to_dict

        return _plain(to_dict(value))
    if isinstance(value, dict):
        return {str(key): _plain(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(item) for item in value]
    tolist = getattr(value, "tolist", None)  # numpy arrays and scalars
    if callable(tolist):
        return _plain(tolist())
    return repr(value)
