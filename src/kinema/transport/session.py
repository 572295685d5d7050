"""Zenoh sessions: join the Kinema router, or host it in this process.

Topology (the same as ROS 2 with rmw_zenoh): one **router** listens on ``tcp/127.0.0.1:7447``; every
process opens one **peer** session that connects to it and, through gossip, talks directly to the other
peers. ``kinema run`` hosts the router in its own process (a zenoh-python session in ``router`` mode) or,
when something already listens there (another Kinema, or ``rmw_zenohd``), joins it as a peer.

Multicast scouting is always off, so nothing leaves loopback unless an endpoint says so and separate test
runs on different ports never see each other. Timestamping is on because latched (transient local)
topics need it.

Environment: ``KINEMA_ZENOH_CONNECT`` (comma-separated endpoints, default ``tcp/127.0.0.1:7447``),
``ROS_DOMAIN_ID`` (default 0), ``KINEMA_ZENOH_CONFIG`` (a zenoh JSON5 config file used as the base).
"""

from __future__ import annotations

import itertools
import json
import logging
import os
import threading
import time
import weakref
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, Literal

from kinema.errors import TransportError, zenoh_message
from kinema.transport.exposure import ExposureError, check_listeners

if TYPE_CHECKING:
    import zenoh

    from kinema.interfaces import TypeRegistry
    from kinema.transport.graph import GraphCache

log = logging.getLogger(__name__)

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"
ENV_CONNECT = "KINEMA_ZENOH_CONNECT"
ENV_CONFIG = "KINEMA_ZENOH_CONFIG"
ENV_DOMAIN = "ROS_DOMAIN_ID"
# Peers listen on an ephemeral loopback port so that gossip can link them directly; without a listen
# key a zenoh peer would listen on every interface.
PEER_LISTEN = "tcp/127.0.0.1:0"

Mode = Literal["peer", "client", "router"]

_open_sessions: weakref.WeakSet[Session] = weakref.WeakSet()
_exit_hook_lock = threading.Lock()
_exit_hook_installed = False


def _close_all_at_exit() -> None:
    for session in list(_open_sessions):
        session.close()


def _install_exit_hook() -> None:
    """Close forgotten sessions before the interpreter joins threads.

    zenoh-python runs each callback entity on a non-daemon thread; an unclosed session would make
    ``threading._shutdown`` wait forever. ``atexit`` runs too late, ``threading._register_atexit`` (what
    ``concurrent.futures`` uses) runs first.
    """
    global _exit_hook_installed
    with _exit_hook_lock:
        if _exit_hook_installed:
            return
        register = getattr(threading, "_register_atexit", None)
        if register is not None:
            try:
                register(_close_all_at_exit)
            except RuntimeError:
                return  # the interpreter is already shutting down; nothing left to hook into
        _exit_hook_installed = True


_handed_out: set[tuple[str, int]] = set()


def free_endpoint(host: str = "127.0.0.1") -> str:
    """``tcp/<host>:<port>`` on a port the OS reports free now (for tests and side-by-side runtimes).

    A port is never handed out twice by one process: the OS may offer a port again as soon as the probe
    closes, before whoever took the first endpoint has started listening on it.
    """
    import socket

    for _ in range(100):
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
            probe.bind((host, 0))
            port = int(probe.getsockname()[1])
        if (host, port) not in _handed_out:
            _handed_out.add((host, port))
            return f"tcp/{host}:{port}"
    raise TransportError(f"no free TCP port on {host} that this process has not handed out already")


def resolve_endpoints(connect: str | Sequence[str] | None) -> list[str]:
    """Endpoints to connect to: the argument, else ``KINEMA_ZENOH_CONNECT``, else the default router."""
    if connect is None:
        connect = os.environ.get(ENV_CONNECT) or DEFAULT_ENDPOINT
    items = connect.split(",") if isinstance(connect, str) else list(connect)
    endpoints = [item.strip() for item in items if item.strip()]
    for endpoint in endpoints:
        if "/" not in endpoint:
            raise TransportError(
                f"bad zenoh endpoint {endpoint!r}: expected <protocol>/<address>, e.g. {DEFAULT_ENDPOINT}"
            )
    return endpoints


def resolve_domain_id(domain_id: int | None) -> int:
    """The ROS domain id: the argument, else ``ROS_DOMAIN_ID``, else 0."""
    if domain_id is not None:
        value: Any = domain_id
    else:
        value = os.environ.get(ENV_DOMAIN, "").strip() or 0
    try:
        resolved = int(value)
    except ValueError:
        raise TransportError(f"{ENV_DOMAIN}={value!r} is not an integer (valid: 0-232)") from None
    if not 0 <= resolved <= 232:
        raise TransportError(f"ROS domain id {resolved} is out of range (valid: 0-232)")
    return resolved


#: Messages at least this large go through zenoh's shared memory (zenoh's default is 3 kB). Below it a copy
#: over loopback costs microseconds; above 3 kB the cell's frequent messages (transforms, joint states of
#: larger robots, node tables) went through the sender's 16 MiB pool at advancing offsets, so every process
#: reading them came to hold the whole pool resident: 16 MB of the agent's memory for what fits in a few
#: pages. Camera images and point clouds, where shared memory pays, are far larger.
SHARED_MEMORY_THRESHOLD_BYTES = 64 << 10
SHARED_MEMORY_THRESHOLD_KEY = "transport/shared_memory/transport_optimization/message_size_threshold"


def build_config(
    mode: Mode,
    *,
    listen: Iterable[str] = (),
    connect: Iterable[str] = (),
    config_file: str | None = None,
    overrides: Mapping[str, Any] | None = None,
) -> zenoh.Config:
    """A zenoh config for Kinema: loopback by default, multicast off, gossip and timestamping on.

    ``config_file`` (JSON5, zenoh's own format) is the base when given; ``overrides`` maps zenoh config
    paths (``"transport/link/tls/root_ca_certificate"``) to JSON values and is applied last.
    """
    import zenoh

    config_file = config_file or os.environ.get(ENV_CONFIG) or None
    try:
        config = zenoh.Config.from_file(config_file) if config_file else zenoh.Config()
    except Exception as error:
        raise TransportError(f"{config_file}: cannot load zenoh config: {zenoh_message(error)}") from error
    settings: dict[str, Any] = {
        "mode": mode,
        "scouting/multicast/enabled": False,
        "scouting/gossip/enabled": True,
        # Multicast is off, so there is nothing to wait for when opening.
        "scouting/delay": 0,
        "timestamping/enabled": True,
    }
    if not config_file:
        settings[SHARED_MEMORY_THRESHOLD_KEY] = SHARED_MEMORY_THRESHOLD_BYTES
    listen = list(listen)
    connect = list(connect)
    if listen or not config_file:
        settings["listen/endpoints"] = listen
    if connect or not config_file:
        settings["connect/endpoints"] = connect
    settings.update(overrides or {})
    for key, value in settings.items():
        try:
            config.insert_json5(key, json.dumps(value))
        except Exception as error:
            raise TransportError(f"bad zenoh config value {key}={value!r}: {error}") from error
    return config


class Session:
    """One zenoh session plus what every Kinema node on it shares (domain id, ids, graph cache).

    Create it with :func:`open_session` or :func:`host_router`; close it (or use ``with``) when done.
    Closing closes every node created on it.
    """

    def __init__(
        self,
        raw: zenoh.Session,
        *,
        domain_id: int,
        mode: Mode,
        endpoints: Sequence[str] = (),
        listen: Sequence[str] = (),
    ) -> None:
        self.zenoh = raw
        self.domain_id = domain_id
        self.mode: Mode = mode
        self.endpoints = list(endpoints)
        self.listen = list(listen)
        # Listeners beyond loopback opened without mutual TLS and access rules (only with ``insecure``).
        self.exposed: list[str] = []
        self.zid = str(raw.info.zid())
        self._ids = itertools.count()
        # Re-entrant: creating the graph cache (under the lock) registers its dispatch thread.
        self._lock = threading.RLock()
        self._closers: list[Any] = []
        self._graph: GraphCache | None = None
        self._dispatchers: list[threading.Thread] = []
        self._closed = False
        _open_sessions.add(self)
        _install_exit_hook()

    @property
    def is_router(self) -> bool:
        """True when this process hosts the router."""
        return self.mode == "router"

    @property
    def closed(self) -> bool:
        """True once :meth:`close` ran."""
        return self._closed

    @property
    def registry(self) -> TypeRegistry:
        """The interface registry (all bundled interfaces loaded)."""
        from kinema.interfaces import load_interfaces

        return load_interfaces()

    def next_entity_id(self) -> int:
        """Session-wide counter for node and entity ids, as rmw_zenoh numbers them."""
        with self._lock:
            return next(self._ids)

    def graph_cache(self) -> GraphCache:
        """The live view of the ROS graph (created on first use)."""
        with self._lock:
            if self._graph is None:
                from kinema.transport.graph import GraphCache

                self._graph = GraphCache(self)
            return self._graph

    def live_graph_cache(self) -> GraphCache | None:
        """The live view of the ROS graph if this session keeps one already (never creates it)."""
        with self._lock:
            return self._graph

    def _track_dispatcher(self, thread: threading.Thread) -> None:
        with self._lock:
            self._dispatchers = [t for t in self._dispatchers if t.is_alive()]
            self._dispatchers.append(thread)

    def _register_closer(self, closer: Any) -> None:
        with self._lock:
            self._closers.append(closer)

    def _unregister_closer(self, closer: Any) -> None:
        with self._lock:
            if closer in self._closers:
                self._closers.remove(closer)

    def node_count(self) -> int:
        """Open nodes on this session."""
        from kinema.transport.node import Node

        with self._lock:
            return sum(isinstance(closer, Node) for closer in self._closers)

    def connected_routers(self) -> list[str]:
        """Zenoh ids of the routers this session is linked to."""
        return [str(zid) for zid in self.zenoh.info.routers_zid()]

    def connected_peers(self) -> list[str]:
        """Zenoh ids of the peers this session is linked to directly."""
        return [str(zid) for zid in self.zenoh.info.peers_zid()]

    def close(self) -> None:
        """Close every node and the zenoh session; safe to call twice."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            closers = list(reversed(self._closers))
            self._closers.clear()
            graph = self._graph
        for closer in closers:
            try:
                closer.close()
            except Exception:
                log.exception("error while closing %r", closer)
        if graph is not None:
            graph.close()
        try:
            self.zenoh.close()
        except Exception:
            log.exception("error while closing the zenoh session")
        _open_sessions.discard(self)
        # The dispatch threads wake up with their channels closed and leave zenoh's code; wait for that,
        # because a thread still inside it when the interpreter finalises aborts the process. A thread
        # busy in a user callback is left alone (it is a daemon).
        with self._lock:
            dispatchers, self._dispatchers = self._dispatchers, []
        deadline = time.monotonic() + 2.0
        current = threading.current_thread()
        for thread in dispatchers:
            if thread is not current:
                thread.join(max(0.0, deadline - time.monotonic()))

    def __enter__(self) -> Session:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        role = (
            f"router on {','.join(self.listen)}"
            if self.is_router
            else f"{self.mode} → {','.join(self.endpoints) or '-'}"
        )
        return f"<kinema Session {self.zid[:8]} domain {self.domain_id} {role}>"


def _open_raw(config: zenoh.Config, what: str) -> zenoh.Session:
    import zenoh

    if os.environ.get("RUST_LOG"):
        # zenoh logs (TLS handshakes, links) only once asked to: RUST_LOG=zenoh=debug shows why a link
        # fails. Once per process; a second call is refused quietly.
        zenoh.try_init_log_from_env()
    try:
        return zenoh.open(config)
    except zenoh.ZError as error:
        raise TransportError(f"cannot open a zenoh session ({what}): {zenoh_message(error)}") from error


def open_session(
    connect: str | Sequence[str] | None = None,
    domain_id: int | None = None,
    *,
    mode: Literal["peer", "client"] | None = None,
    listen: Sequence[str] | None = None,
    config_file: str | None = None,
    config_overrides: Mapping[str, Any] | None = None,
    connect_timeout: float = 2.0,
    insecure: bool = False,
) -> Session:
    """Join the Kinema zenoh network (the router at ``connect``) and return the session.

    Args:
        connect: endpoint(s) of the router; default ``KINEMA_ZENOH_CONNECT`` or ``tcp/127.0.0.1:7447``.
            An empty list opens a standalone session (in-process use only).
        domain_id: ROS domain id; default ``ROS_DOMAIN_ID`` or 0.
        mode: ``peer`` (direct links to other peers via gossip) or ``client`` (everything through the
            router). Default: ``client`` when the config file says so (a client config of ``kinema
            security init``: its traffic must pass the router's access rules), else ``peer``.
        listen: peer listen endpoints; default one ephemeral loopback port.
        config_file: zenoh JSON5 config used as the base (default ``KINEMA_ZENOH_CONFIG``).
        config_overrides: zenoh config paths → values, applied last.
        connect_timeout: how long to wait for the link to a router or peer (seconds).
        insecure: allow listening beyond loopback without mutual TLS and access rules (see
            :mod:`kinema.transport.exposure`).

    Raises:
        TransportError: nothing answers at the endpoints within ``connect_timeout``.
        ExposureError: a listener beyond loopback without mutual TLS and access rules.
    """
    from_file = bool(config_file or os.environ.get(ENV_CONFIG))
    if mode is None:
        mode = (
            "client" if _file_mode(config_file or os.environ.get(ENV_CONFIG) or None) == "client" else "peer"
        )
    if connect is None and from_file and not os.environ.get(ENV_CONNECT):
        endpoints: list[str] = []  # the config file says where to connect
    else:
        endpoints = resolve_endpoints(connect) if connect is None or connect else []
    domain = resolve_domain_id(domain_id)
    if listen is not None:
        listen_endpoints = list(listen)
    else:
        listen_endpoints = [PEER_LISTEN] if mode == "peer" and not from_file else []
    config = build_config(
        mode, listen=listen_endpoints, connect=endpoints, config_file=config_file, overrides=config_overrides
    )
    file_mode = _file_mode(config_file or os.environ.get(ENV_CONFIG) or None)
    if (
        from_file
        and listen is None
        and mode == "peer"
        and (file_mode == "router" or _listen_is_default(config))
    ):
        # zenoh's default peer listener is every interface, and a router's file (what `kinema run` hosts
        # with) names the router's own endpoints: a peer keeps one ephemeral loopback port instead.
        config.insert_json5("listen/endpoints", json.dumps([PEER_LISTEN]))
        listen_endpoints = [PEER_LISTEN]
    if from_file and not endpoints:
        endpoints = _configured_endpoints(config, "connect/endpoints", mode)
    check_listeners(config, _configured_endpoints(config, "listen/endpoints", mode), insecure=insecure)
    where = ", ".join(endpoints) or "no endpoint"
    try:
        raw = _open_raw(config, f"{mode} connecting to {where}")
    except TransportError as error:
        if "Unable to connect to any of" in str(error):  # a client whose router does not answer
            raise TransportError(_no_router_message(where, endpoints, config)) from None
        raise
    session = Session(raw, domain_id=domain, mode=mode, endpoints=endpoints, listen=listen_endpoints)
    if endpoints:
        deadline = time.monotonic() + connect_timeout
        while not (session.connected_routers() or session.connected_peers()):
            if time.monotonic() >= deadline:
                session.close()
                raise TransportError(_no_router_message(where, endpoints, config))
            time.sleep(0.005)
    return session


def _no_router_message(where: str, endpoints: Sequence[str], config: zenoh.Config) -> str:
    """Why nothing answered, with what to do: over TLS, a router may be there and refuse the handshake
    (a certificate of another CA, an expired one, files that are not there), which looks the same."""
    message = (
        f"no Kinema router answers at {where} (start one with `kinema run`, or point --connect / "
        f"{ENV_CONNECT} at a running one)"
    )
    if not any(endpoint.startswith("tls/") for endpoint in endpoints):
        return message
    missing = [path for path in _tls_files(config) if not os.path.isfile(path)]
    if missing:
        return f"{message}; the TLS files of {ENV_CONFIG} are not there: {', '.join(missing)}"
    return (
        f"{message}; if one runs there, it refused this machine's certificate: check that {ENV_CONFIG} is "
        "a client config of that cell's `kinema security init` (same CA, not expired)"
    )


def _tls_files(config: zenoh.Config) -> list[str]:
    """The certificate and key files a zenoh config names for its TLS links (inline ones are not files)."""
    import zenoh

    try:
        tls = json.loads(config.get_json("transport/link/tls"))
    except (zenoh.ZError, ValueError):
        return []
    keys = ("root_ca_certificate", "connect_certificate", "connect_private_key")
    return [str(tls[key]) for key in keys if isinstance(tls, dict) and isinstance(tls.get(key), str)]


def host_router(
    listen: str | Sequence[str] | None = None,
    domain_id: int | None = None,
    *,
    connect: Sequence[str] = (),
    config_file: str | None = None,
    config_overrides: Mapping[str, Any] | None = None,
    insecure: bool = False,
) -> Session:
    """Host the zenoh router in this process and return its session (usable like any other).

    Args:
        listen: endpoint(s) to listen on; default ``tcp/127.0.0.1:7447``, or the config file's.
        connect: other routers to link to (multi-machine, or two routers on one host).
        insecure: allow listening beyond loopback without mutual TLS and access rules (the session's
            ``exposed`` lists such listeners, for a warning).

    Raises:
        TransportError: the endpoint is taken (another router runs there) or invalid.
        ExposureError: a listener beyond loopback without mutual TLS and access rules, and not
            ``insecure`` (see :mod:`kinema.transport.exposure`).
    """
    from_file = bool(config_file or os.environ.get(ENV_CONFIG))
    # With a config file and no explicit endpoint, the file's own listen endpoints apply.
    listen_endpoints = resolve_endpoints(listen) if listen else ([] if from_file else [DEFAULT_ENDPOINT])
    domain = resolve_domain_id(domain_id)
    config = build_config(
        "router",
        listen=listen_endpoints,
        connect=list(connect),
        config_file=config_file,
        overrides=config_overrides,
    )
    if not listen_endpoints:
        listen_endpoints = _configured_endpoints(config, "listen/endpoints", "router")
    exposed = check_listeners(config, listen_endpoints, insecure=insecure)
    raw = _open_raw(config, f"router listening on {', '.join(listen_endpoints) or 'no endpoint'}")
    session = Session(raw, domain_id=domain, mode="router", endpoints=list(connect), listen=listen_endpoints)
    session.exposed = exposed
    return session


def default_endpoints() -> list[str]:
    """Where :func:`open_session` connects when given no endpoint: ``KINEMA_ZENOH_CONNECT``, else the
    connect endpoints of the ``KINEMA_ZENOH_CONFIG`` file, else ``tcp/127.0.0.1:7447``."""
    config_file = os.environ.get(ENV_CONFIG)
    if config_file and not os.environ.get(ENV_CONNECT):
        import zenoh

        try:
            config = zenoh.Config.from_file(config_file)
            mode = str(json.loads(config.get_json("mode")))
            found = _configured_endpoints(config, "connect/endpoints", mode)
        except Exception:  # open_session says what is wrong with the file
            found = []
        if found:
            return found
    return resolve_endpoints(None)


def _file_mode(config_file: str | None) -> str:
    """The mode a zenoh config file sets (``peer``, zenoh's default, when none or unreadable)."""
    if not config_file:
        return "peer"
    import zenoh

    try:
        return str(json.loads(zenoh.Config.from_file(config_file).get_json("mode")))
    except Exception:
        return "peer"  # build_config reports a bad file with its message


def _listen_is_default(config: zenoh.Config) -> bool:
    """True when ``config`` keeps zenoh's default listen endpoints (its file does not set any)."""
    import zenoh

    return bool(config.get_json("listen/endpoints") == zenoh.Config().get_json("listen/endpoints"))


def _configured_endpoints(config: zenoh.Config, key: str, mode: str) -> list[str]:
    """Endpoints a zenoh config sets for ``mode`` (a plain list, or a per-mode map)."""
    value = json.loads(config.get_json(key))
    if isinstance(value, dict):
        value = value.get(mode, [])
    return [str(item) for item in value or []]


def host_or_join(
    endpoint: str | None = None,
    domain_id: int | None = None,
    *,
    config_file: str | None = None,
    config_overrides: Mapping[str, Any] | None = None,
    insecure: bool = False,
    before_join: Callable[[str], None] | None = None,
) -> Session:
    """Host the router at ``endpoint``, or join the one already listening there (what ``kinema run`` does).

    ``endpoint`` defaults to the first of ``KINEMA_ZENOH_CONNECT`` or ``tcp/127.0.0.1:7447``; several
    comma-separated endpoints are all listened on (and joined through). A router this process may not
    host (a listener beyond loopback without mutual TLS, see :mod:`kinema.transport.exposure`) is still
    joined when one runs there (that is connecting, not listening); when none does, the refusal is
    raised. ``before_join`` is called with the endpoint before joining (what it raises is raised, and
    nothing is joined).
    """
    target = endpoint or resolve_endpoints(None)[0]
    try:
        return host_router(
            target, domain_id, config_file=config_file, config_overrides=config_overrides, insecure=insecure
        )
    except ExposureError as refusal:
        log.info("not hosting a router at %s (%s); trying to join one that runs there", target, refusal)
        if before_join is not None:
            before_join(target)
        try:
            return open_session(target, domain_id, config_file=config_file, config_overrides=config_overrides)
        except TransportError:
            raise refusal from None
    except TransportError as hosting_error:
        log.info("cannot host the router at %s (%s); joining it", target, hosting_error)
        if before_join is not None:
            before_join(target)
        try:
            return open_session(target, domain_id, config_file=config_file, config_overrides=config_overrides)
        except TransportError as joining_error:
            raise TransportError(
                f"cannot host a router at {target} ({hosting_error}) nor join one there ({joining_error})"
            ) from joining_error
