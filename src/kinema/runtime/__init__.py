"""The runtime: the objective server (the "agent"), its streams, and ``kinema run``'s process supervisor.

Names are imported on first use, so light modules of this package (``names``, ``quick_protocol``,
``result``) can be imported without the engine or the transport. See ``docs/runtime.md``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from kinema.lazy_exports import LazyExports

_EXPORTS = {
    "Agent": "kinema.runtime.agent",
    "AgentOptions": "kinema.runtime.agent_process",
    "build_agent": "kinema.runtime.agent_process",
    "FactoryTreeSource": "kinema.runtime.objective_server",
    "ObjectiveRequest": "kinema.runtime.objective_server",
    "ObjectiveRun": "kinema.runtime.objective_server",
    "ObjectiveServer": "kinema.runtime.objective_server",
    "LibraryTreeSource": "kinema.runtime.objective_source",
    "Launcher": "kinema.runtime.launcher",
    "LaunchOptions": "kinema.runtime.launcher",
    "MoveItErrorCode": "kinema.runtime.error_codes",
    "ObjectiveStatus": "kinema.runtime.objective_status",
    "ObjectiveResult": "kinema.runtime.result",
    "ParameterOverride": "kinema.runtime.overrides",
    "SimClock": "kinema.runtime.sim_clock",
}
_lazy = LazyExports(__name__, _EXPORTS)

__all__ = [
    "Agent",
    "AgentOptions",
    "FactoryTreeSource",
    "LaunchOptions",
    "Launcher",
    "LibraryTreeSource",
    "MoveItErrorCode",
    "ObjectiveRequest",
    "ObjectiveResult",
    "ObjectiveRun",
    "ObjectiveServer",
    "ObjectiveStatus",
    "ParameterOverride",
    "SimClock",
    "build_agent",
]

if TYPE_CHECKING:
    from kinema.runtime.agent import Agent
    from kinema.runtime.agent_process import AgentOptions, build_agent
    from kinema.runtime.error_codes import MoveItErrorCode
    from kinema.runtime.launcher import Launcher, LaunchOptions
    from kinema.runtime.objective_server import (
        FactoryTreeSource,
        ObjectiveRequest,
        ObjectiveRun,
        ObjectiveServer,
    )
    from kinema.runtime.objective_source import LibraryTreeSource
    from kinema.runtime.objective_status import ObjectiveStatus
    from kinema.runtime.overrides import ParameterOverride
    from kinema.runtime.result import ObjectiveResult
    from kinema.runtime.sim_clock import SimClock


def __getattr__(name: str) -> Any:
    return _lazy.attribute(name)


def __dir__() -> list[str]:
    return __all__
