"""meshcat's server (its ZMQ/WebSocket bridge) in a thread, bound to 127.0.0.1 only, with Kinema's page.

meshcat's own ``zmqserver`` serves the viewer's static files (bundled in the installed package, so it
works offline) and relays drawing commands to every open page; its file server, though, listens on all
interfaces. :class:`MeshcatServer` runs the same bridge with both its HTTP port and its ZMQ port on
loopback, and adds:

- ``/static/``: Kinema's page (meshcat's viewer plus a status banner, framed on the scene's camera);
- ``/kinema/status.json`` and ``/kinema/view.json``: what the banner and the camera read;
- :meth:`MeshcatServer.send`: a direct path for the bridge's own process (no ZMQ round trip per command,
  which costs ~0.3 ms each); other programs can still draw into the scene through :attr:`zmq_url` with
  ``meshcat.Visualizer(zmq_url=...)``.
"""

from __future__ import annotations

import asyncio
import contextlib
import io
import json
import logging
import threading
from collections.abc import Callable, Sequence
from importlib import resources
from typing import Any

from kinema.errors import KinemaError

log = logging.getLogger("kinema.viz")

HOST = "127.0.0.1"
# meshcat's own defaults; taken ports are skipped upwards.
DEFAULT_HTTP_PORT = 7000
DEFAULT_ZMQ_PORT = 6000
START_TIMEOUT_S = 10.0

# (command type, path, msgpack payload) as meshcat's bridge takes them from ZMQ.
Command = tuple[str, str, bytes]


def _page() -> bytes:
    return resources.files("kinema.viz").joinpath("viewer.html").read_bytes()


class MeshcatServer:
    """meshcat's bridge on 127.0.0.1 in a daemon thread (see the module docstring).

    Args:
        port: the HTTP port; None takes the first free one from 7000 up.
        status: returns the JSON the page's banner shows (called on the server thread).
        view: returns the JSON the page frames its camera with.

    Raises:
        KinemaError: ``port`` is taken or the server cannot start.
    """

    def __init__(
        self,
        port: int | None = None,
        status: Callable[[], dict[str, Any]] | None = None,
        view: Callable[[], dict[str, Any]] | None = None,
    ) -> None:
        self._status = status or (lambda: {})
        self._view = view or (lambda: {})
        self._bridge: Any = None
        self._loop: Any = None
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, args=(port,), name="kinema-meshcat", daemon=True)
        self._thread.start()
        if not self._ready.wait(START_TIMEOUT_S):
            raise KinemaError(f"the meshcat server did not start within {START_TIMEOUT_S:.0f} s")
        if self._error is not None:
            if isinstance(self._error, OSError) and port is not None:
                raise KinemaError(
                    f"cannot serve the 3D view on {HOST}:{port} ({self._error.strerror or self._error}); "
                    "pick another --port, or leave it out to take a free one"
                ) from self._error
            raise KinemaError(f"the meshcat server failed to start: {self._error}") from self._error

    @property
    def url(self) -> str:
        """The page to open, ``http://127.0.0.1:<port>/static/``."""
        return str(self._bridge.web_url)

    @property
    def port(self) -> int:
        """The HTTP port."""
        return int(self._bridge.fileserver_port)

    @property
    def zmq_url(self) -> str:
        """Where ``meshcat.Visualizer(zmq_url=...)`` can draw into the same scene."""
        return str(self._bridge.zmq_url)

    @property
    def clients(self) -> int:
        """Pages connected now."""
        return len(self._bridge.websocket_pool) if self._bridge is not None else 0

    def send(self, commands: Sequence[Command]) -> None:
        """Apply drawing commands to the scene (and to every open page); thread-safe, returns at once."""
        if commands and self._loop is not None:
            self._loop.add_callback(self._apply, list(commands))

    def stop(self) -> None:
        """Stop serving and close the sockets."""
        loop, self._loop = self._loop, None
        if loop is not None:
            loop.add_callback(loop.stop)
        self._thread.join(timeout=5.0)

    # -- the server thread ---------------------------------------------------------------------------

    def _run(self, port: int | None) -> None:
        asyncio.set_event_loop(asyncio.new_event_loop())
        try:
            # meshcat prints "Port: N in use, trying another..." for every taken port it skips.
            with contextlib.redirect_stderr(io.StringIO()):
                bridge = _make_bridge(port, self)
        except BaseException as error:
            self._error = error
            self._ready.set()
            return
        self._bridge = bridge
        self._loop = bridge.ioloop
        self._ready.set()
        try:
            bridge.run()
        finally:
            bridge.zmq_stream.close()
            bridge.zmq_socket.close(linger=0)
            for server in bridge.http_servers:
                server.stop()
            asyncio.get_event_loop().close()

    def _apply(self, commands: list[Command]) -> None:
        from meshcat.servers.tree import SceneTree, find_node

        bridge = self._bridge
        for kind, path_text, data in commands:
            path = [part for part in path_text.split("/") if part]
            if kind == "set_object":
                node = find_node(bridge.tree, path)
                if node.object == data:
                    continue  # meshcat's own cache rule: an identical object is not sent again
                node.object = data
                node.properties = []
            elif kind == "set_transform":
                find_node(bridge.tree, path).transform = data
            elif kind == "set_property":
                find_node(bridge.tree, path).properties.append(data)
            elif kind == "delete":
                if path:
                    parent = find_node(bridge.tree, path[:-1])
                    if path[-1] in parent:
                        del parent[path[-1]]
                else:
                    bridge.tree = SceneTree()
            for socket in list(bridge.websocket_pool):
                try:
                    socket.write_message(data, binary=True)
                except Exception as error:  # a page that just closed: it is dropped from the pool
                    log.debug("dropping a closed meshcat page: %s", error)


def _make_bridge(port: int | None, owner: MeshcatServer) -> Any:
    """Construct the bridge on this thread's event loop (tornado binds the loop at construction)."""
    import tornado.web
    from meshcat.servers import zmqserver

    class PageHandler(tornado.web.RequestHandler):
        def get(self) -> None:
            self.set_header("Content-Type", "text/html; charset=utf-8")
            self.set_header("Cache-Control", "no-store")
            self.write(_page())

    class NoIconHandler(tornado.web.RequestHandler):
        def get(self) -> None:
            self.set_status(204)  # browsers ask for one; a 404 would be logged on every page load

    class JsonHandler(tornado.web.RequestHandler):
        def initialize(self, source: Callable[[], dict[str, Any]]) -> None:
            self.source = source

        def get(self) -> None:
            self.set_header("Content-Type", "application/json")
            self.set_header("Cache-Control", "no-store")
            self.write(json.dumps(self.source()))

    class LoopbackApplication(tornado.web.Application):
        def __init__(self, handlers: list[Any]) -> None:
            super().__init__(handlers)
            self.http_servers: list[Any] = []

        def listen(self, port: int, address: str = "", **kwargs: Any) -> Any:  # type: ignore[override]
            # meshcat calls listen(port) without an address, i.e. every interface: keep it on loopback.
            server = super().listen(port, address=HOST, **kwargs)
            self.http_servers.append(server)
            return server

    class QuietWebSocketHandler(zmqserver.WebSocketHandler):  # type: ignore[misc]
        # meshcat's handler prints every page that opens or closes on stderr.
        def open(self) -> None:
            self.bridge.websocket_pool.add(self)
            self.bridge.send_scene(self)

        def on_close(self) -> None:
            self.bridge.websocket_pool.discard(self)

    class LoopbackBridge(zmqserver.ZMQWebSocketBridge):  # type: ignore[misc]
        def make_app(self) -> Any:
            static = {"path": zmqserver.VIEWER_ROOT, "default_filename": zmqserver.VIEWER_HTML}
            return LoopbackApplication(
                [
                    (r"/static/", PageHandler),
                    (r"/static/(.*)", zmqserver.StaticFileHandlerNoCache, static),
                    (r"/favicon\.ico", NoIconHandler),
                    (r"/kinema/status\.json", JsonHandler, {"source": owner._status}),
                    (r"/kinema/view\.json", JsonHandler, {"source": owner._view}),
                    (r"/", QuietWebSocketHandler, {"bridge": self}),
                ]
            )

        @property
        def http_servers(self) -> list[Any]:
            return list(self.app.http_servers)

    return LoopbackBridge(host=HOST, port=port)
