"""Waypoints: the config package's named joint states."""

from __future__ import annotations

from .retrieve_waypoint import RetrieveWaypoint

BEHAVIORS = (RetrieveWaypoint,)
