"""Camera: the latest image of an image topic, drawn in the terminal.

The picture is drawn with the best method the terminal has (textual-image): Sixel or the Kitty graphics
protocol where supported, coloured half blocks otherwise. ``KINEMA_TUI_IMAGE`` (``auto``, ``sixel``,
``tgp``, ``halfcell``, ``unicode``) forces one, for terminals that answer the queries wrongly (tmux).
Only the newest frame is kept; the screen redraws at most :data:`REDRAW_PERIOD_S` apart, and stops
watching (so a simulated camera stops rendering) while it is hidden.
"""

from __future__ import annotations

import os
import threading
from typing import Any

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.message import Message
from textual.screen import Screen
from textual.widgets import Select, Static

from kinema.tui.connection import CameraImage, ConnectionState
from kinema.tui.screens.base import RuntimeView
from kinema.tui.widgets.key_footer import KeyFooter

_image_widgets: Any = None
_image_unavailable = ""


def load_image_support() -> str:
    """Import textual-image, which asks the terminal once what images it can draw; '' when it can, else
    why not.

    Its questions are answered on the terminal's input, so they must be asked while no app reads it:
    before an app starts (``kinema ui --camera``), or inside ``App.suspend()`` (the app's first camera
    view). Later calls return the first answer.
    """
    global _image_widgets, _image_unavailable
    if _image_widgets is None and not _image_unavailable:
        try:
            import textual_image.widget as widgets
        except Exception as error:  # a closed stdout and the like: the screen says why instead
            _image_unavailable = f"cannot draw images in this terminal: {error}"
        else:
            _image_widgets = widgets
    return _image_unavailable


def image_support_loaded() -> bool:
    """Whether textual-image was imported (and the terminal asked) already."""
    return _image_widgets is not None or bool(_image_unavailable)


REDRAW_PERIOD_S = 0.2
METHODS = ("auto", "sixel", "tgp", "halfcell", "unicode")


def image_widget_class(method: str | None = None) -> Any:
    """The textual-image widget class for ``method`` (default: ``KINEMA_TUI_IMAGE``, else ``auto``).

    Raises:
        ValueError: an unknown method, naming the valid ones.
    """
    chosen = (method or os.environ.get("KINEMA_TUI_IMAGE", "") or "auto").strip().lower()
    if chosen not in METHODS:
        raise ValueError(f"KINEMA_TUI_IMAGE={chosen!r} is not a drawing method; valid: {', '.join(METHODS)}")
    if load_image_support():
        return None
    return {
        "auto": _image_widgets.Image,
        "sixel": _image_widgets.SixelImage,
        "tgp": _image_widgets.TGPImage,
        "halfcell": _image_widgets.HalfcellImage,
        "unicode": _image_widgets.UnicodeImage,
    }[chosen]


class TopicsListed(Message):
    """The runtime's image topics arrived."""

    def __init__(self, topics: list[str]) -> None:
        super().__init__()
        self.topics = topics


class WatchStarted(Message):
    """Watching a topic began; ``end`` ends it (not ``stop``: Message.stop() stops the message's
    bubbling)."""

    def __init__(self, topic: str, end: Any) -> None:
        super().__init__()
        self.topic = topic
        self.end = end


class CameraScreen(RuntimeView, Screen[None]):
    """The newest picture of one image topic, with its size, frame and time."""

    BINDINGS = [
        Binding("r", "refresh_topics", "Topics", id="camera.topics", tooltip="List the image topics again"),
        Binding("escape", "close", "Close", id="camera.close", tooltip="Close the camera view"),
    ]

    DEFAULT_CSS = """
    CameraScreen #camera-toolbar { height: 3; }
    CameraScreen #camera-topic { width: 48; }
    CameraScreen #camera-caption { padding: 1 1 0 1; }
    CameraScreen #camera-picture { width: 1fr; height: 1fr; }
    CameraScreen #camera-placeholder { padding: 1 2; }
    """

    def __init__(self, topic: str | None = None, method: str | None = None) -> None:
        super().__init__()
        self.topic = topic
        self.widget_class = image_widget_class(method)
        self.frames = 0
        self.shown: CameraImage | None = None
        self._latest: CameraImage | None = None
        self._lock = threading.Lock()
        self._stop_watching: Any = None
        self._watching = ""

    def compose(self) -> ComposeResult:
        yield Static(Text("Camera", style="bold"), classes="pane-title")
        with Vertical(classes="main"):
            with Horizontal(id="camera-toolbar"):
                yield Select[str]([], prompt="Image topic", id="camera-topic")
                yield Static("", id="camera-caption", classes="muted")
            if self.widget_class is None:
                yield Static(load_image_support(), id="camera-placeholder")
            else:
                yield Static("Choose an image topic.", id="camera-placeholder")
                picture = self.widget_class(id="camera-picture")
                picture.display = False
                yield picture
        yield KeyFooter()

    def on_mount(self) -> None:
        self.set_interval(REDRAW_PERIOD_S, self._redraw)
        self.app.register_view(self)  # type: ignore[attr-defined]
        if self._connected():
            self.action_refresh_topics()
        else:  # `kinema ui --camera` opens this before the connection is up: runtime_connected lists
            self._placeholder("Waiting for the runtime ...")

    def runtime_connected(self) -> None:
        """The runtime (re)appeared: list its image topics again and watch the chosen one anew (a watch of
        the previous connection ended with it)."""
        self.action_refresh_topics()
        if self.topic and self.is_current:
            self.watch_topic(self.topic)

    def _connected(self) -> bool:
        return self.app.status.state is ConnectionState.CONNECTED  # type: ignore[attr-defined, no-any-return]

    @property
    def connection(self) -> Any:
        return self.app.connection  # type: ignore[attr-defined]

    # -- topics ------------------------------------------------------------------------------------

    def action_refresh_topics(self) -> None:
        self._in_worker("List image topics", self.connection.image_topics, TopicsListed)

    def _in_worker(self, what: str, call: Any, done: Any) -> None:
        def work() -> None:
            try:
                result = call()
            except Exception as error:  # shown, never raised: the runtime may be gone
                self.app.notify(str(error), title=f"{what} failed", severity="error", timeout=8)
                return
            self.post_message(done(result))

        self.run_worker(work, thread=True, group=what, name=what)

    def on_topics_listed(self, message: TopicsListed) -> None:
        topics = list(message.topics)
        if self.topic and self.topic not in topics:
            topics.insert(0, self.topic)  # asked for by name: it may start publishing later
        select = self.query_one("#camera-topic", Select)
        select.set_options([(topic, topic) for topic in topics])
        if not topics:
            self._placeholder("No image topic now (is a camera running?). Press r to look again.")
        wanted = self.topic or (topics[0] if len(topics) == 1 else None)
        if wanted:
            select.value = wanted

    def on_select_changed(self, event: Select.Changed) -> None:
        if isinstance(event.value, str) and event.value != self._watching:
            self.watch_topic(event.value)

    # -- watching ----------------------------------------------------------------------------------

    def watch_topic(self, topic: str) -> None:
        """Show ``topic`` from now on (not ``watch``: that is Textual's DOMNode.watch)."""
        self._unwatch()
        self.topic = topic
        self._watching = topic
        self._placeholder(f"Waiting for an image on {topic} ...")

        def start() -> Any:
            return self.connection.watch_images(topic, self._receive)

        self._in_worker(f"Watch {topic}", start, lambda stop: WatchStarted(topic, stop))

    def on_watch_started(self, message: WatchStarted) -> None:
        if message.topic != self._watching:  # switched again meanwhile
            message.end()
            return
        self._stop_watching = message.end

    def _receive(self, image: CameraImage) -> None:
        """A transport thread's picture: keep only the newest."""
        with self._lock:
            if image.topic == self._watching:
                self._latest = image
                self.frames += 1

    def _unwatch(self) -> None:
        stop, self._stop_watching = self._stop_watching, None
        self._watching = ""
        if stop is not None:
            try:
                stop()
            except Exception:  # the session may be gone already
                pass

    def on_screen_suspend(self) -> None:
        self._unwatch()

    def on_screen_resume(self) -> None:
        if self.topic and not self._watching and self._connected():
            self.watch_topic(self.topic)

    def on_unmount(self) -> None:
        self.app.unregister_view(self)  # type: ignore[attr-defined]
        self._unwatch()

    def action_close(self) -> None:
        self._unwatch()
        self.app.pop_screen()

    # -- drawing -----------------------------------------------------------------------------------

    def _placeholder(self, text: str) -> None:
        for placeholder in self.query("#camera-placeholder"):
            placeholder.update(text)  # type: ignore[attr-defined]
            placeholder.display = True
        for picture in self.query("#camera-picture"):
            picture.display = False

    def _redraw(self) -> None:
        with self._lock:
            image, self._latest = self._latest, None
            frames = self.frames
        if image is None or self.widget_class is None:
            return
        from PIL import Image as PilImage

        picture = self.query_one("#camera-picture")
        picture.image = PilImage.fromarray(image.pixels)  # type: ignore[attr-defined]
        picture.display = True
        self.query_one("#camera-placeholder").display = False
        height, width = image.pixels.shape[:2]
        caption = Text(f"{width}x{height} {image.encoding}", style="bold")
        caption.append(f"  {image.frame_id}  t={image.stamp:.2f} s  frames {frames}", style="dim")
        self.query_one("#camera-caption", Static).update(caption)
        self.shown = image
