"""``QuickClient``: start, cancel and query objectives over the agent's private JSON endpoints.

It imports zenoh and the standard library only (no ROS type system, no numpy), so a short-lived
process such as ``kinema objective do`` starts in a fraction of the time :class:`ObjectiveClient` needs.
It offers what a command line needs; programs that want streams, handles of ``/do_objective`` goals or
interoperability with ROS tools use :class:`~kinema.sdk.ObjectiveClient`.
"""

from __future__ import annotations

import os
import re
import time
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from kinema.errors import TransportError, zenoh_message
from kinema.runtime import quick_protocol as quick
from kinema.runtime.objective_status import ObjectiveStatus
from kinema.runtime.overrides import ParameterOverride
from kinema.runtime.result import ObjectiveResult

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"
_FOREVER = 365 * 24 * 3600.0
_RETRY_PAUSE = 0.02


def _endpoints(connect: str | None) -> list[str]:
    text = connect or os.environ.get("KINEMA_ZENOH_CONNECT") or DEFAULT_ENDPOINT
    return [item.strip() for item in text.split(",") if item.strip()]


def _domain(domain_id: int | None) -> int:
    if domain_id is not None:
        return domain_id
    value = os.environ.get("ROS_DOMAIN_ID", "").strip() or "0"
    try:
        return int(value)
    except ValueError:
        raise TransportError(f"ROS_DOMAIN_ID={value!r} is not an integer (valid: 0-232)") from None


_MAIN_TREE = re.compile(r"""main_tree_to_execute\s*=\s*["']([^"']+)["']""")
_TREE_IDS = re.compile(r"""<BehaviorTree\b[^>]*?\bID\s*=\s*["']([^"']+)["']""")


def xml_objective_name(xml: str) -> str:
    """The name the agent will report for an XML objective (found without loading the BT engine)."""
    head = xml[:65536]
    found = _MAIN_TREE.search(head)
    if found:
        return found.group(1)
    ids = _TREE_IDS.findall(head)
    return ids[0] if len(ids) == 1 else "<objective XML>"


class QuickRun:
    """A run started by :meth:`QuickClient.start`."""

    def __init__(self, client: QuickClient, replies: Any, run_id: int, objective_name: str) -> None:
        self._client = client
        self._replies = replies
        self.run_id = run_id
        self.objective_name = objective_name

    def result(self, on_toast: Callable[[str, str], None] | None = None) -> ObjectiveResult:
        """Wait until the run ends and return its result.

        Args:
            on_toast: called with ``(level, text)`` for each toast a behavior publishes meanwhile
                (level ``info``, ``warn`` or ``failure``).

        Raises:
            TransportError: the agent went away before answering.
        """
        for reply in self._replies:
            if reply.ok is None:
                raise TransportError(f"the agent failed: {reply.err.payload.to_string()}")
            body = quick.decode(reply.ok.payload.to_bytes())
            if body.get("event") == "log" and on_toast is not None:
                on_toast(str(body.get("level", "info")), str(body.get("text", "")))
            if body.get("event") == "result":
                return ObjectiveResult(
                    int(body["error_code"]), str(body["error_message"]), str(body["objective_name"])
                )
        raise TransportError(f"the agent went away before objective {self.objective_name!r} ended")

    def cancel(self) -> bool:
        """Cancel this run; False when it already ended."""
        body = self._client._ask(quick.CANCEL, {"run_id": self.run_id})
        return bool(body["cancelled"])


class QuickClient:
    """A light connection to the agent for one-shot commands. Close it (or use ``with``) when done.

    Args:
        connect: router endpoint(s) (default ``KINEMA_ZENOH_CONNECT`` or ``tcp/127.0.0.1:7447``).
        timeout: how long to wait for the router and the agent before raising TransportError.
        domain_id: ROS domain id (default ``ROS_DOMAIN_ID`` or 0).
    """

    def __init__(
        self, connect: str | None = None, *, timeout: float = 5.0, domain_id: int | None = None
    ) -> None:
        import json

        import zenoh

        self.timeout = timeout
        self.domain_id = _domain(domain_id)
        # KINEMA_ZENOH_CONFIG (e.g. a client config of `kinema security init`: TLS, certificates) is the
        # base, as for every other Kinema session; its endpoints apply unless others are given.
        config_file = os.environ.get("KINEMA_ZENOH_CONFIG")
        try:
            config = zenoh.Config.from_file(config_file) if config_file else zenoh.Config()
        except zenoh.ZError as error:
            raise TransportError(f"{config_file}: cannot load zenoh config: {zenoh_message(error)}") from None
        if config_file and connect is None and not os.environ.get("KINEMA_ZENOH_CONNECT"):
            self.endpoints = [str(e) for e in json.loads(config.get_json("connect/endpoints")) or []]
        else:
            self.endpoints = _endpoints(connect)
        settings = {
            "mode": "client",
            "connect/endpoints": self.endpoints,
            "scouting/multicast/enabled": False,
            "connect/timeout_ms": int(timeout * 1000),
        }
        for path, value in settings.items():
            config.insert_json5(path, json.dumps(value))
        try:
            self._session = zenoh.open(config)
        except zenoh.ZError:
            raise TransportError(self._no_runtime("no Kinema router answers")) from None

    def _no_runtime(self, what: str) -> str:
        return (
            f"{what} at {', '.join(self.endpoints)} (start one with `kinema run`, "
            "or point --connect / KINEMA_ZENOH_CONNECT at a running one)"
        )

    def _get(self, operation: str, payload: dict[str, Any], timeout: float) -> Any:
        """Send a query, retrying while no agent matches (it may still be starting); return the replies."""
        import zenoh

        key = quick.key(self.domain_id, operation)
        deadline = time.monotonic() + self.timeout
        while True:
            replies = self._session.get(
                key,
                payload=quick.encode(payload),
                target=zenoh.QueryTarget.BEST_MATCHING,  # one server, as ServiceClient (QUERY_TARGET)
                consolidation=zenoh.ConsolidationMode.NONE,
                timeout=timeout,
            )
            first = next(iter(replies), None)
            if first is not None:
                return first, replies
            if time.monotonic() + _RETRY_PAUSE >= deadline:
                what = f"no Kinema runtime answered within {self.timeout:g} s"
                raise TransportError(self._no_runtime(what))
            time.sleep(_RETRY_PAUSE)

    def _ask(self, operation: str, payload: dict[str, Any]) -> dict[str, Any]:
        first, _ = self._get(operation, payload, self.timeout)
        if first.ok is None:
            raise TransportError(f"the agent refused: {first.err.payload.to_string()}")
        return quick.decode(first.ok.payload.to_bytes())

    def start(
        self,
        name: str = "",
        overrides: Mapping[str, Any] | Iterable[ParameterOverride] | None = None,
        *,
        xml: str = "",
    ) -> QuickRun:
        """Start an objective by name, or an XML string (the name wins if both are set).

        XML goes to the ``start_xml`` key: a separate grant, which an operator's certificate may lack.
        """
        items = (
            [ParameterOverride(str(k), v) for k, v in overrides.items()]
            if isinstance(overrides, Mapping)
            else list(overrides or ())
        )
        payload = {
            "objective_name": name,
            "objective_xml": "" if name else xml,
            "overrides": [
                {"name": o.name, "value": o.value, "behavior_namespaces": list(o.behavior_namespaces)}
                for o in items
            ],
        }
        try:
            first, replies = self._get(quick.START if name else quick.START_XML, payload, _FOREVER)
        except TransportError:
            if name:
                raise
            self._explain_xml_refusal()
            raise
        if first.ok is None:
            raise TransportError(f"the agent refused the request: {first.err.payload.to_string()}")
        body = quick.decode(first.ok.payload.to_bytes())
        return QuickRun(self, replies, int(body["run_id"]), name or xml_objective_name(xml))

    def _explain_xml_refusal(self) -> None:
        """When the runtime answers but not on ``start_xml``, the access rules dropped the XML: say so."""
        try:
            self._ask(quick.STATUS, {})
        except TransportError:
            return
        raise TransportError(
            "the runtime answers, but not to ad-hoc objective XML: this machine's certificate lacks that "
            "grant (`kinema security` on the robot lists the roles; `kinema security init --allow-xml NAME` "
            "gives it). Run a library objective by name instead: kinema objective run NAME"
        )

    def cancel(self) -> tuple[bool, str]:
        """Cancel whatever runs; ``(cancelled, objective name)``."""
        body = self._ask(quick.CANCEL, {})
        return bool(body["cancelled"]), str(body["objective_name"])

    def status(self) -> tuple[ObjectiveStatus, str]:
        """``(status, objective name)`` of the objective server right now."""
        status, name, _warnings = self.status_report()
        return status, name

    def status_report(self) -> tuple[ObjectiveStatus, str, list[str]]:
        """``(status, objective name, watchdog warnings)``: the warnings name stuck behaviors."""
        body = self._ask(quick.STATUS, {})
        warnings = [str(warning) for warning in body.get("warnings", ())]
        return ObjectiveStatus(body["status"]), str(body["objective_name"]), warnings

    def runtime_configs(self, timeout: float = 1.0) -> list[str]:
        """The config packages the agents on this network run (from their presence tokens; an agent
        that declares none, an older Kinema or MoveIt Pro's, is not listed)."""
        from kinema.transport.presence import AGENT, PRESENCE_PREFIX, parse_presence

        replies = self._session.liveliness().get(f"{PRESENCE_PREFIX}/{self.domain_id}/**", timeout=timeout)
        members = [parse_presence(str(reply.ok.key_expr)) for reply in replies if reply.ok is not None]
        return sorted({m.config for m in members if m is not None and m.role == AGENT and m.config})

    def close(self) -> None:
        """Close the session."""
        self._session.close()

    def __enter__(self) -> QuickClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
