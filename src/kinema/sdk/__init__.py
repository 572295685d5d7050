"""The Python SDK: start, cancel and watch objectives of a running Kinema from any process.

``ObjectiveClient`` (the ROS interfaces: ``/execute_objective``, ``/do_objective``, the heartbeat and
streams) is what programs and ``kinema shell`` use; ``QuickClient`` (the agent's JSON endpoints, no ROS
type system to load) is what one-shot commands such as ``kinema objective run`` use. Results are typed
(:class:`ObjectiveResult`: ``succeeded`` / ``cancelled`` / ``failed``, the MoveIt error code and message).

Names are imported on first use, so ``import kinema.sdk.quick`` stays cheap.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from kinema.lazy_exports import LazyExports

_EXPORTS = {
    "BlackboardSnapshot": "kinema.sdk.streams",
    "BlackboardValue": "kinema.sdk.streams",
    "LogEntry": "kinema.sdk.streams",
    "MessageStream": "kinema.sdk.streams",
    "NodeStatusChange": "kinema.sdk.streams",
    "NodeStatusChanges": "kinema.sdk.streams",
    "NodeStatusDecoder": "kinema.sdk.streams",
    "ServerStatus": "kinema.sdk.streams",
    "MoveItErrorCode": "kinema.runtime.error_codes",
    "ObjectivePort": "kinema.config.objective_file",
    "ObjectiveStatus": "kinema.runtime.objective_status",
    "ParameterOverride": "kinema.runtime.overrides",
    "ObjectiveResult": "kinema.runtime.result",
    "ObjectiveClient": "kinema.sdk.client",
    "ObjectiveHandle": "kinema.sdk.client",
    "ObjectiveTimeoutError": "kinema.sdk.client",
    "parameter_messages": "kinema.sdk.client",
    "QuickClient": "kinema.sdk.quick",
    "QuickRun": "kinema.sdk.quick",
}
_lazy = LazyExports(__name__, _EXPORTS)

__all__ = [
    "BlackboardSnapshot",
    "BlackboardValue",
    "LogEntry",
    "MessageStream",
    "MoveItErrorCode",
    "NodeStatusChange",
    "NodeStatusChanges",
    "NodeStatusDecoder",
    "ObjectiveClient",
    "ObjectiveHandle",
    "ObjectivePort",
    "ObjectiveResult",
    "ObjectiveStatus",
    "ObjectiveTimeoutError",
    "ParameterOverride",
    "QuickClient",
    "QuickRun",
    "ServerStatus",
    "parameter_messages",
]

if TYPE_CHECKING:
    from kinema.config.objective_file import ObjectivePort
    from kinema.runtime.error_codes import MoveItErrorCode
    from kinema.runtime.objective_status import ObjectiveStatus
    from kinema.runtime.overrides import ParameterOverride
    from kinema.runtime.result import ObjectiveResult
    from kinema.sdk.client import ObjectiveClient, ObjectiveHandle, ObjectiveTimeoutError, parameter_messages
    from kinema.sdk.quick import QuickClient, QuickRun
    from kinema.sdk.streams import (
        BlackboardSnapshot,
        BlackboardValue,
        LogEntry,
        MessageStream,
        NodeStatusChange,
        NodeStatusChanges,
        NodeStatusDecoder,
        ServerStatus,
    )


def __getattr__(name: str) -> Any:
    return _lazy.attribute(name)


def __dir__() -> list[str]:
    return __all__
