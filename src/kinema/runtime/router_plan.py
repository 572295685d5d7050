"""How ``kinema run`` listens: which endpoints its router opens, and which one its own processes join.

``--connect`` (or ``KINEMA_ZENOH_CONNECT``) may name several comma-separated endpoints. Loopback ones
are for this machine; a ``tls/`` (or ``quic/``) one opens the cell to other machines with the security
folder's certificates and access rules (``kinema security init``), and then a loopback listener is
added for the agent, the drivers and local tools, which join over plain TCP on loopback (the access
rules let local processes do everything). Anything else beyond loopback is refused by the transport
unless ``--insecure`` (see :mod:`kinema.transport.exposure`). Without ``--connect`` and
``KINEMA_ZENOH_CONNECT``, a router's ``KINEMA_ZENOH_CONFIG`` file decides where the router listens; a
client's (another machine of the cell, with its certificate) makes ``kinema run -n``/``-o`` join over TLS.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from kinema.errors import KinemaError, TransportError

if TYPE_CHECKING:
    from kinema.transport import Session


@dataclass(frozen=True)
class RouterPlan:
    """What to host.

    Attributes:
        listen: the endpoints the router listens on.
        local: the endpoint this machine's processes (agent, drivers, tools) join.
        config_file: the zenoh config with the TLS settings and access rules (None: plain loopback).
    """

    listen: tuple[str, ...]
    local: str
    config_file: Path | None = None


def plan_router(endpoint: str | None, security_dir: Path | None = None) -> RouterPlan:
    """The plan for ``kinema run --connect ENDPOINT`` (None: ``KINEMA_ZENOH_CONNECT`` or the default).

    Raises:
        KinemaError: a TLS endpoint and no security folder (with the command that makes one).
    """
    from kinema.transport import DEFAULT_ENDPOINT, resolve_endpoints
    from kinema.transport.exposure import TLS_PROTOCOLS, is_loopback, split_endpoint
    from kinema.transport.security_folder import ROUTER_CONFIG, default_security_dir

    from_file = _zenoh_config_file() if endpoint is None else None
    endpoints = _router_endpoints(from_file) if from_file is not None else resolve_endpoints(endpoint)
    secure = [e for e in endpoints if split_endpoint(e)[0] in TLS_PROTOCOLS]
    local = next((e for e in endpoints if split_endpoint(e)[0] == "tcp" and is_loopback(e)), None)
    if local is None:
        local = _loopback_twin(endpoints)
    config_file = from_file
    listen = list(endpoints)
    joining_with_certificates = bool(os.environ.get("KINEMA_ZENOH_CONFIG")) and from_file is None
    if secure and config_file is None and not joining_with_certificates:
        folder = security_dir or default_security_dir()
        config_file = folder / ROUTER_CONFIG
        if not config_file.is_file():
            host = split_endpoint(secure[0])[1]
            unspecified = host.strip("[]") in ("0.0.0.0", "::")
            # A certificate names the addresses clients dial: every address of this machine by default,
            # never 0.0.0.0 (listening there is fine once the certificate covers the real ones).
            init = "kinema security init" if unspecified else f"kinema security init --address {host}"
            raise KinemaError(
                f"listening on {secure[0]} needs the certificates and access rules of a security folder, "
                f"and {folder} has none: run `{init}` first (or pass --security DIR)"
            )
    if secure and local is None and not joining_with_certificates:
        environment = resolve_endpoints(None)[0] if os.environ.get("KINEMA_ZENOH_CONNECT") else ""
        local = environment if environment and is_loopback(environment) else DEFAULT_ENDPOINT
        listen.insert(0, local)
    return RouterPlan(tuple(listen), local or endpoints[0], config_file)


def _zenoh_config_file() -> Path | None:
    """``KINEMA_ZENOH_CONFIG`` when it is a router's config and decides where the router listens (no
    ``KINEMA_ZENOH_CONNECT``). A client's config (another machine's, with its certificate) only joins."""
    import json

    import zenoh

    configured = os.environ.get("KINEMA_ZENOH_CONFIG")
    if not configured or os.environ.get("KINEMA_ZENOH_CONNECT"):
        return None
    path = Path(configured).expanduser()
    try:
        mode = json.loads(zenoh.Config.from_file(str(path)).get_json("mode"))
    except Exception as error:
        raise TransportError(f"{path}: cannot load zenoh config: {error}") from None
    return path if mode == "router" else None


def _router_endpoints(config_file: Path) -> list[str]:
    """The endpoints a zenoh config file has a router listen on."""
    import zenoh

    from kinema.transport import DEFAULT_ENDPOINT
    from kinema.transport.exposure import listen_endpoints_of

    try:
        config = zenoh.Config.from_file(str(config_file))
    except Exception as error:
        raise TransportError(f"{config_file}: cannot load zenoh config: {error}") from None
    if config.get_json("listen/endpoints") == zenoh.Config().get_json("listen/endpoints"):
        return [DEFAULT_ENDPOINT]  # the file does not choose: Kinema's default, not zenoh's (every interface)
    return listen_endpoints_of(config, "router") or [DEFAULT_ENDPOINT]


def _loopback_twin(endpoints: list[str]) -> str | None:
    """``tcp/127.0.0.1:P`` for a TCP listener on every interface (``0.0.0.0``/``[::]``), which includes it."""
    from kinema.transport.exposure import split_endpoint

    for endpoint in endpoints:
        protocol, host, port = split_endpoint(endpoint)
        if protocol == "tcp" and host in ("0.0.0.0", "::") and port is not None:
            return f"tcp/127.0.0.1:{port}"
    return None


def open_router(
    plan: RouterPlan, *, insecure: bool = False, before_join: Callable[[str], None] | None = None
) -> Session:
    """Host the planned router, or join the one already running at ``plan.local``.

    ``before_join`` is called with the endpoint before joining a running router (what it raises is
    raised, and nothing is joined).

    Raises:
        ExposureError: a listener beyond loopback without mutual TLS and access rules, not ``insecure``.
        TransportError: it can neither be hosted nor joined.
    """
    from kinema.transport import host_or_join, host_router, open_session
    from kinema.transport.exposure import ExposureError

    if plan.config_file is None:
        return host_or_join(",".join(plan.listen), insecure=insecure, before_join=before_join)
    try:
        return host_router(list(plan.listen), config_file=str(plan.config_file), insecure=insecure)
    except ExposureError:
        raise
    except TransportError as hosting_error:
        if before_join is not None:
            before_join(plan.local)
        try:
            return open_session(plan.local)  # a runtime hosts it already (one per cell decides next)
        except TransportError:
            raise hosting_error from None
