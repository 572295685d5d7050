"""The agent's private JSON endpoints: the same operations as ``/do_objective`` without ROS types.

A client that only wants to start, cancel or watch one objective (``kinema objective ...``, a shell
script) should not pay for loading the ROS type system (rosbags and numpy take most of a cold start). The
agent therefore also answers plain zenoh queries in a private key space, with JSON payloads, as the
transport reference recommends for Kinema-internal traffic. These keys are not part of the ROS graph;
ROS programs use ``/do_objective`` and ``/execute_objective``.

* ``kinema/<domain>/objective_server/start`` — payload ``{"objective_name", "overrides": [{"name",
  "value", "behavior_namespaces"}]}``: a library objective by name; the agent replies ``{"event":
  "accepted", "run_id"}`` at once, ``{"event": "log", "level": "info|warn|failure", "text"}`` for each
  toast a behavior publishes while the run lasts, then ``{"event": "result", "error_code",
  "error_message", "objective_name"}`` when the run ends.
* ``kinema/<domain>/objective_server/start_xml`` — the same with ``"objective_xml"`` (a BT.CPP v4
  document) instead of a name. Ad-hoc XML has a key of its own because it is a separate grant: the access
  rules of ``kinema security init`` give it to named clients only (``start`` refuses XML).
* ``kinema/<domain>/objective_server/cancel`` — payload ``{"run_id"}`` (or ``{}`` for whatever runs);
  reply ``{"cancelled": bool, "objective_name"}``.
* ``kinema/<domain>/objective_server/status`` — reply ``{"status", "objective_name"}``.

This module imports only the standard library; both sides share it.
"""

from __future__ import annotations

import json
from typing import Any

START = "start"
START_XML = "start_xml"
CANCEL = "cancel"
STATUS = "status"


def key(domain_id: int, operation: str) -> str:
    """The zenoh key of one operation."""
    return f"kinema/{domain_id}/objective_server/{operation}"


def encode(payload: dict[str, Any]) -> bytes:
    """JSON bytes."""
    return json.dumps(payload, separators=(",", ":")).encode()


def decode(data: bytes) -> dict[str, Any]:
    """A JSON object; raises ValueError for anything else."""
    from kinema.nesting import loads_json

    value = loads_json(data.decode() if data else "{}", "the request")
    if not isinstance(value, dict):
        raise ValueError("expected a JSON object")
    return value
