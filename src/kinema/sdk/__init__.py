"""The Python SDK: start, cancel and watch objectives of a running Kinema from any process.

``ObjectiveClient`` is what ``kinema objective ...`` and ``kinema shell`` use; results are typed
(:class:`ObjectiveResult`: ``succeeded`` / ``cancelled`` / ``failed``, the MoveIt error code and message).
"""

from __future__ import annotations

from kinema.runtime.error_codes import MoveItErrorCode
from kinema.runtime.objective_status import ObjectiveStatus
from kinema.runtime.overrides import ParameterOverride
from kinema.runtime.result import ObjectiveResult
from kinema.sdk.client import ObjectiveClient, ObjectiveHandle, parameter_messages
from kinema.sdk.quick import QuickClient, QuickRun
from kinema.sdk.streams import BlackboardSnapshot, BlackboardValue, LogEntry, MessageStream, ServerStatus

__all__ = [
    "BlackboardSnapshot",
    "BlackboardValue",
    "LogEntry",
    "MessageStream",
    "MoveItErrorCode",
    "ObjectiveClient",
    "ObjectiveHandle",
    "ObjectiveResult",
    "ObjectiveStatus",
    "ParameterOverride",
    "QuickClient",
    "QuickRun",
    "ServerStatus",
    "parameter_messages",
]
