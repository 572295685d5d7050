"""``kinema view`` as a library: attach to a runtime, serve its scene with meshcat, open the browser.

::

    viewer = start_viewer(ViewerOptions(endpoint="tcp/127.0.0.1:7447", open_browser=False))
    print(viewer.url)          # http://127.0.0.1:7000/static/
    ...
    viewer.close()

:func:`run_viewer` does the same and blocks until Ctrl-C or SIGTERM (what the CLI and ``kinema run`` use).
"""

from __future__ import annotations

import logging
import os
import sys
import threading
import webbrowser
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from kinema.errors import ConfigError, KinemaError
from kinema.process.stop import TERMINATE, StopRequest

log = logging.getLogger("kinema.viz")


@dataclass
class ViewerOptions:
    """What ``kinema view`` attaches to and how it serves.

    Attributes:
        endpoint: the runtime's router (None: ``KINEMA_ZENOH_CONNECT`` or tcp/127.0.0.1:7447).
        config: the config package whose MuJoCo scene is drawn (None: the running instance's, else the
            active one).
        workspace: the workspace to resolve it in (None: the active one).
        port: the HTTP port (None: the first free one from 7000 up).
        open_browser: open the page in the default browser.
        frame_rate: most scene updates per second sent to the page.
        echo: prints the URL and notices.
    """

    endpoint: str | None = None
    config: str | None = None
    workspace: Path | None = None
    port: int | None = None
    open_browser: bool = True
    frame_rate: float = 60.0
    echo: Callable[[str], None] = field(default=print)


@dataclass
class SceneSource:
    """The config drawn, its MuJoCo scene, start keyframe and end effector (for planned paths)."""

    config: str
    model_path: Path
    keyframe: str | None
    end_effector: str | None


def resolve_scene(config: str | None, workspace: Path | None, endpoint: str) -> SceneSource:
    """Find the MuJoCo scene to draw (see :attr:`ViewerOptions.config` for which config).

    Raises:
        ConfigError: the config cannot be resolved or has no MuJoCo scene.
    """
    from kinema.config import Workspace, active_selection, resolve_config

    selection = active_selection(workspace, config)
    name = config
    if name is None:
        from kinema.runtime.instance import running_instances

        # What the runtime at the endpoint runs, in its workspace: `kinema run -c example_config` in a
        # workspace is drawn and named as example_config, not as the selected (or default) config.
        matching = [r for r in running_instances() if _same_endpoint(r.router, endpoint) and r.config]
        if matching:
            name = matching[-1].config
            if workspace is None and matching[-1].workspace:
                selection = active_selection(Path(matching[-1].workspace), name)
        else:
            name = selection.config
    if not name:
        raise ConfigError("no config selected: pass -c NAME (or select one with `kinema configure`)")
    found = Workspace.discover(selection.workspace) if selection.workspace else Workspace.bundled_only()
    resolved = resolve_config(name, found, check_files=False)
    model_path = resolved.mujoco_model_path
    if model_path is None:
        raise ConfigError(
            f"config {name!r} has no MuJoCo scene to draw: set hardware.simulation.mujoco_model "
            "({package, path})",
            location=resolved.location_of("hardware"),
        )
    keyframe = resolved.get("hardware.simulation.mujoco_keyframe")
    return SceneSource(name, model_path, str(keyframe) if keyframe else None, _end_effector(resolved))


def _same_endpoint(a: str, b: str) -> bool:
    """``tcp/localhost:7447`` and ``tcp/127.0.0.1:7447`` name one router (as do 0.0.0.0 listeners)."""

    def normal(endpoint: str) -> str:
        for alias in ("localhost", "0.0.0.0", "[::1]", "[::]"):
            endpoint = endpoint.replace(f"/{alias}:", "/127.0.0.1:")
        return endpoint.strip()

    return normal(a) == normal(b)


def _end_effector(resolved: Any) -> str | None:
    """The SRDF's first end effector's parent link, else the first chain group's tip (None: neither)."""
    from kinema.motion.srdf import parse_srdf

    try:
        semantic = parse_srdf(resolved.srdf_path)
    except Exception as error:  # no or broken SRDF: the path is drawn for a guessed tool instead
        log.info("no end effector from the SRDF (%s); guessing the tool per trajectory", error)
        return None
    if semantic.end_effectors:
        return semantic.end_effectors[0].parent_link
    for group in semantic.groups.values():
        if group.chains:
            return group.chains[-1][1]
    return None


class Viewer:
    """A running ``kinema view``: the session, the meshcat server and the bridge between them."""

    def __init__(self, options: ViewerOptions) -> None:
        from kinema.transport import open_session, resolve_endpoints
        from kinema.viz.meshcat_server import MeshcatServer
        from kinema.viz.scene_model import SceneModel
        from kinema.viz.scene_viewer import SceneViewer

        self.endpoint = options.endpoint or resolve_endpoints(None)[0]
        self.source = resolve_scene(options.config, options.workspace, self.endpoint)
        scene = SceneModel.from_file(self.source.model_path, self.source.end_effector, self.source.keyframe)
        self.session = open_session(self.endpoint)
        self.bridge: SceneViewer | None = None
        try:
            self.server = MeshcatServer(options.port, status=lambda: self._status(), view=scene.camera_view)
            self.bridge = SceneViewer(
                self.session,
                scene,
                self.server,
                endpoint=self.endpoint,
                config=self.source.config,
                frame_rate=options.frame_rate,
            )
            self.bridge.start()
        except BaseException:
            self.close()
            raise
        self._options = options
        self._redraw_lock = threading.Lock()
        self._watch_agent_config()

    def _watch_agent_config(self) -> None:
        """Follow the config the runtime's agent runs: after `kinema down` and `kinema run -c OTHER` the
        page draws OTHER's scene (unless ``-c`` chose what to draw), or says why it cannot."""
        from kinema.transport.dispatch import channel, dispatch
        from kinema.transport.presence import AGENT, PRESENCE_PREFIX

        key = f"{PRESENCE_PREFIX}/{self.session.domain_id}/*/{AGENT}/**"
        try:
            watch = self.session.zenoh.liveliness().declare_subscriber(key, channel(), history=True)
        except Exception:
            log.warning("cannot watch the runtime's config; the view keeps drawing %s", self.source.config)
            return
        self._agent_watch = watch  # a zenoh subscriber no one holds is undeclared
        self.session._track_dispatcher(dispatch(watch, self._on_agent_presence, "-view-agent"))

    def _on_agent_presence(self, sample: Any) -> None:
        import zenoh

        from kinema.transport.presence import parse_presence

        member = parse_presence(str(sample.key_expr))
        if member is None or sample.kind == zenoh.SampleKind.DELETE or not member.config:
            return
        bridge = self.bridge
        if bridge is not None:
            bridge.runtime_config = member.config
        if self._options.config is None and member.config != self.source.config:
            # Loading a MuJoCo scene takes a while: not on the transport's thread.
            threading.Thread(
                target=self._redraw, args=(member.config,), name="kinema-view-redraw", daemon=True
            ).start()

    def _redraw(self, config: str) -> None:
        """Draw ``config``'s scene instead (the page redraws from scratch), or say on the page why not."""
        from kinema.viz.scene_model import SceneModel
        from kinema.viz.scene_viewer import SceneViewer

        with self._redraw_lock:
            old = self.bridge
            if old is None or config == self.source.config:
                return
            try:
                source = resolve_scene(config, self._options.workspace, self.endpoint)
                scene = SceneModel.from_file(source.model_path, source.end_effector, source.keyframe)
            except KinemaError as error:
                old.follow_note = (
                    f"The runtime runs config {config}, which this view cannot draw ({error}); it draws "
                    f"{self.source.config}."
                )
                self._options.echo(f"warning: {old.follow_note}")
                return
            old.stop()
            bridge = SceneViewer(
                self.session,
                scene,
                self.server,
                endpoint=self.endpoint,
                config=source.config,
                frame_rate=self._options.frame_rate,
            )
            bridge.runtime_config = config
            self.source, self.bridge = source, bridge
            bridge.start()
            self._options.echo(f"3D view now draws config {config} (what the runtime runs)")

    @property
    def url(self) -> str:
        """The page to open."""
        return self.server.url

    def _status(self) -> dict[str, Any]:
        return self.bridge.status() if self.bridge is not None else {}

    def close(self) -> None:
        """Stop following the runtime and stop serving."""
        if self.bridge is not None:
            self.bridge.stop()
            self.bridge = None
        server = getattr(self, "server", None)
        if server is not None:
            server.stop()
        self.session.close()


def start_viewer(options: ViewerOptions) -> Viewer:
    """Attach to the runtime and serve its scene; returns once the page can be opened.

    Raises:
        ConfigError: no MuJoCo scene to draw.
        TransportError: no runtime answers at the endpoint.
        KinemaError: the HTTP port is taken.
    """
    return Viewer(options)


def open_browser(url: str) -> bool:
    """Open ``url`` in a graphical browser; False when there is none (no display on Linux).

    Without a display Python's ``webbrowser`` falls back to text browsers (lynx, w3m) that would take
    over the terminal, which the TUI of ``kinema run`` needs.
    """
    if sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    ):
        return False
    try:
        return webbrowser.open(url, new=2)
    except webbrowser.Error:
        return False


def run_viewer(options: ViewerOptions, ready: Callable[[str], None] | None = None) -> int:
    """Start the viewer, print the URL, open the browser, block until Ctrl-C or SIGTERM; returns 0."""
    viewer = start_viewer(options)
    with StopRequest().handle_signals(TERMINATE) as stop:
        try:
            options.echo(
                f"3D view of {viewer.source.config}: {viewer.url} "
                f"(runtime at {viewer.endpoint}; Ctrl-C to stop)"
            )
            if ready is not None:
                ready(viewer.url)
            if options.open_browser and not open_browser(viewer.url):
                options.echo("no graphical browser here: open the URL above in one")
            stop.wait()
            return 0
        finally:
            viewer.close()
