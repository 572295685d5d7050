"""Who may reach a Kinema router: loopback always; anything beyond only with mutual TLS and access rules.

Whatever reaches the router may run objectives, drive the controllers directly, move the simulation and
erase waypoints. So a session listens beyond loopback (a LAN address, ``0.0.0.0``, ``[::]``) only when
every such listener is a TLS one (``tls/``, ``quic/``) and the zenoh config requires client certificates
(``transport/link/tls/enable_mtls`` with a ``root_ca_certificate`` and the listener's own certificate)
and enables access control with ``default_permission: "deny"``. ``kinema security init`` writes such a
config. The other way is to say so explicitly (``kinema run --insecure``, ``insecure=True``): the
listener opens and a warning says what it exposes.

Connecting to a remote router is not listening, and is never refused here.
"""

from __future__ import annotations

import ipaddress
import json
import logging
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from kinema.errors import TransportError

if TYPE_CHECKING:
    import zenoh

log = logging.getLogger(__name__)

TLS_PROTOCOLS = frozenset({"tls", "quic"})
# Protocols that never leave the machine.
LOCAL_PROTOCOLS = frozenset({"unixsock-stream", "unixpipe", "unixsock-seqpacket", "vsock"})
_TLS_FILES = ("root_ca_certificate", "listen_certificate", "listen_private_key")


class ExposureError(TransportError):
    """A listener beyond loopback without mutual TLS and access rules, and no explicit ``insecure``."""


def split_endpoint(endpoint: str) -> tuple[str, str, int | None]:
    """``tcp/192.168.1.10:7447#iface=eth0`` → ``("tcp", "192.168.1.10", 7447)`` (port None if absent)."""
    protocol, _, rest = endpoint.strip().partition("/")
    address = rest.split("#", 1)[0].split("?", 1)[0]
    host, port = address, None
    if address.startswith("["):
        host, _, tail = address[1:].partition("]")
        if tail.startswith(":") and tail[1:].isdigit():
            port = int(tail[1:])
    elif address.count(":") == 1:
        host, _, text = address.partition(":")
        port = int(text) if text.isdigit() else None
    return protocol.lower(), host, port


def is_loopback(endpoint: str) -> bool:
    """True when a listener at ``endpoint`` can only be reached from this machine."""
    protocol, host, _port = split_endpoint(endpoint)
    if protocol in LOCAL_PROTOCOLS:
        return True
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False  # a host name other than localhost, or something Kinema cannot tell


def listen_endpoints_of(config: zenoh.Config, mode: str) -> list[str]:
    """The endpoints a zenoh config listens on in ``mode`` (a plain list, or a per-mode map)."""
    value = json.loads(config.get_json("listen/endpoints"))
    if isinstance(value, dict):
        value = value.get(mode, [])
    return [str(item) for item in value or []]


def _get(config: zenoh.Config, key: str) -> Any:
    try:
        return json.loads(config.get_json(key))
    except Exception:
        return None


def missing_protection(config: zenoh.Config) -> list[str]:
    """What the config lacks for listening beyond loopback (empty when it has it all)."""
    missing = []
    if _get(config, "transport/link/tls/enable_mtls") is not True:
        missing.append("client certificates (transport.link.tls.enable_mtls: true)")
    absent = [
        name
        for name in _TLS_FILES
        if not (
            _get(config, f"transport/link/tls/{name}") or _get(config, f"transport/link/tls/{name}_base64")
        )
    ]
    if absent:
        missing.append("the TLS files " + ", ".join(f"transport.link.tls.{name}" for name in absent))
    if _get(config, "access_control/enabled") is not True:
        missing.append("access rules (access_control.enabled: true)")
    elif _get(config, "access_control/default_permission") != "deny":
        missing.append('access rules that deny by default (access_control.default_permission: "deny")')
    return missing


def check_listeners(config: zenoh.Config, endpoints: Iterable[str], *, insecure: bool = False) -> list[str]:
    """Refuse listeners beyond loopback that lack mutual TLS and access rules, unless ``insecure``.

    Returns:
        The endpoints that listen beyond loopback without that protection (allowed by ``insecure``);
        the caller warns about them.

    Raises:
        ExposureError: such a listener and not ``insecure``; the message says what is missing and the
            two ways on (``kinema security init``, ``--insecure``).
    """
    exposed = [endpoint for endpoint in endpoints if not is_loopback(endpoint)]
    if not exposed:
        return []
    plain = [endpoint for endpoint in exposed if split_endpoint(endpoint)[0] not in TLS_PROTOCOLS]
    missing = missing_protection(config)
    if not plain and not missing:
        return []
    if insecure:
        for endpoint in exposed:
            log.warning("listening on %s without mutual TLS and access rules (insecure)", endpoint)
        return exposed
    if plain:
        why = f"{', '.join(plain)} is plain TCP: no encryption, no client certificates, no access rules"
    else:
        why = f"its zenoh config lacks {'; '.join(missing)}"
    raise ExposureError(
        f"refusing to listen on {', '.join(exposed)}: beyond loopback a Kinema router listens only with "
        "mutual TLS and access rules, since anyone who reaches it could run objectives, drive the "
        f"controllers and erase waypoints, and {why}. Run `kinema security init` once, then `kinema run "
        "--connect tls/<this machine's address>:7448` (docs/multi-machine.md); or, on a network you trust, "
        "pass --insecure (insecure=True in Python) to listen in plain text anyway"
    )


def insecure_warning(endpoints: Iterable[str]) -> str:
    """What ``kinema run --insecure`` prints about the listeners it opened."""
    return (
        f"WARNING: listening on {', '.join(endpoints)} without TLS client certificates or access rules: "
        "anyone who can reach this port can run objectives, drive the controllers, move the simulation and "
        "erase waypoints. Use `kinema security init` and a tls/ endpoint instead (docs/multi-machine.md)."
    )
