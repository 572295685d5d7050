"""Behavior plugins: hooks, discovery, the behavior registry and hot reload.

Plugin authors need only :data:`hookimpl` and the :class:`RegisterBehavior` callback type; the runtime
uses :class:`BehaviorHost` (load the active loaders, keep the registry current, hot reload) and
:class:`BehaviorRegistry` (populate a fresh factory per objective run).
"""

from __future__ import annotations

from kinema.plugins.discovery import ENTRY_POINT_GROUP, PluginSource, PluginSpec, default_loader_name
from kinema.plugins.events import ReloadEvent, ReloadKind
from kinema.plugins.hookspecs import hookimpl
from kinema.plugins.host import BehaviorHost, LoadReport
from kinema.plugins.registration import BehaviorRegistration, RegisterBehavior
from kinema.plugins.registry import BehaviorRegistry, PluginRecord

__all__ = [
    "ENTRY_POINT_GROUP",
    "BehaviorHost",
    "BehaviorRegistration",
    "BehaviorRegistry",
    "LoadReport",
    "PluginRecord",
    "PluginSource",
    "PluginSpec",
    "RegisterBehavior",
    "ReloadEvent",
    "ReloadKind",
    "default_loader_name",
    "hookimpl",
]
