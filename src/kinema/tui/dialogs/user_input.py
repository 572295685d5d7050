"""What only the user can give a running objective: a pose, joint values, points on a camera image, a
teleoperation session.

Each dialog answers one :class:`~kinema.tui.connection.UserInputRequested` (RetrievePoseParameter,
RetrieveRobotStateParameter, GetPointsFromUser, DoTeleoperateAction of the core behaviors) and returns a
:class:`~kinema.tui.connection.UserInputAnswer`; Escape cancels (the behavior then fails).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from typing import Any

from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label, Static

from kinema.tui.connection import (
    TELEOP_CLOSE_GRIPPER,
    TELEOP_JOINT_VALUES,
    TELEOP_OPEN_GRIPPER,
    TELEOP_TARGET_POSE,
    CameraImage,
    UserInputAnswer,
    UserInputRequested,
)


def _numbers(text: str, count: int, what: str) -> tuple[float, ...]:
    """``count`` numbers written with spaces or commas.

    Raises:
        ValueError: a sentence naming ``what`` and how to write it.
    """
    parts = text.replace(",", " ").split()
    try:
        values = tuple(float(part) for part in parts)
    except ValueError:
        values = ()
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise ValueError(f"{what}: give {count} numbers separated by spaces, e.g. {' '.join(['0'] * count)}")
    return values


def _text(values: tuple[float, ...]) -> str:
    return " ".join(f"{v:.4f}".rstrip("0").rstrip(".") if v else "0" for v in values)


class _UserInputDialog(ModalScreen[UserInputAnswer]):
    BINDINGS = [Binding("escape", "cancel", "Cancel", id="dialog.cancel", tooltip="Give nothing")]

    def __init__(self, request: UserInputRequested) -> None:
        super().__init__()
        self.request = request

    def compose_title(self) -> ComposeResult:
        yield Label(self.request.prompt, classes="dialog-title")
        yield Label(f"{self.request.behavior} at {self.request.node_path}", classes="dialog-keys")

    def action_cancel(self) -> None:
        self.dismiss(UserInputAnswer(False, "cancelled in the TUI"))


class _FormDialog(_UserInputDialog):
    """A question answered with a form: OK, or Enter in its last field, gives the answer (``_give``);
    Enter in another field moves on; Cancel or Escape cancels. The handlers live here only: Textual calls
    a message handler on every class of the MRO, so the form dialogs define none of their own."""

    def compose_buttons(self) -> ComposeResult:
        with Horizontal(classes="dialog-buttons"):
            yield Button("OK", variant="primary", id="ok")
            yield Button("Cancel (Esc)", id="cancel")

    def is_last_field(self, field: Input) -> bool:
        """Whether Enter in ``field`` gives the answer (by default Enter in any field does)."""
        return True

    def on_input_submitted(self, event: Input.Submitted) -> None:
        event.stop()
        if self.is_last_field(event.input):
            self._give()
        else:
            self.focus_next()

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        if event.button.id == "ok":
            self._give()
        else:
            self.action_cancel()

    def _give(self) -> None:
        raise NotImplementedError


class PoseDialog(_FormDialog):
    """A target pose: frame, position (m) and orientation (quaternion x y z w), prefilled with the tool's
    pose now. Enter in the last field or OK gives it."""

    def compose(self) -> ComposeResult:
        request = self.request
        with Vertical(classes="dialog wide"):
            yield from self.compose_title()
            yield Label("Frame")
            yield Input(request.frame_id, id="pose-frame")
            yield Label("Position x y z (m)")
            yield Input(_text(request.position), id="pose-position")
            yield Label("Orientation x y z w (quaternion)")
            yield Input(_text(request.orientation), id="pose-orientation")
            yield from self.compose_buttons()

    def on_mount(self) -> None:
        self.set_focus(self.query_one("#pose-position", Input))

    def is_last_field(self, field: Input) -> bool:
        return field.id == "pose-orientation"

    def _give(self) -> None:
        frame = self.query_one("#pose-frame", Input).value.strip() or "world"
        try:
            position = _numbers(self.query_one("#pose-position", Input).value, 3, "Position")
            orientation = _numbers(self.query_one("#pose-orientation", Input).value, 4, "Orientation")
        except ValueError as error:
            self.notify(str(error), severity="warning")
            return
        if math.sqrt(sum(v * v for v in orientation)) < 1e-9:
            self.notify("Orientation: all zeros is no quaternion; 0 0 0 1 is no rotation", severity="warning")
            return
        self.dismiss(
            UserInputAnswer(True, "", frame, position, orientation)  # type: ignore[arg-type]
        )


class JointStateDialog(_FormDialog):
    """A value per joint (rad, or m for a prismatic joint), each prefilled with where the joint is now.
    Enter in the last field or OK gives them."""

    def compose(self) -> ComposeResult:
        request = self.request
        with Vertical(classes="dialog wide"):
            yield from self.compose_title()
            for index, (name, value) in enumerate(
                zip(request.joint_names, request.joint_positions, strict=False)
            ):
                yield Label(name)
                yield Input(_text((value,)), id=f"joint-{index}")
            yield from self.compose_buttons()

    def on_mount(self) -> None:
        if self.request.joint_names:
            self.set_focus(self.query_one("#joint-0", Input))

    def is_last_field(self, field: Input) -> bool:
        return field.id == f"joint-{len(self.request.joint_names) - 1}"

    def _give(self) -> None:
        values: list[float] = []
        for index, name in enumerate(self.request.joint_names):
            try:
                (value,) = _numbers(self.query_one(f"#joint-{index}", Input).value, 1, name)
            except ValueError as error:
                self.notify(str(error), severity="warning")
                return
            values.append(value)
        self.dismiss(UserInputAnswer(True, "", joint_positions=tuple(values)))


class PointsDialog(_FormDialog):
    """One pixel per prompt on the latest image of the request's topic: click the image (the pixel under
    the pointer, as near as the terminal's cells allow) or type ``column row`` into the point's field."""

    DEFAULT_CSS = """
    PointsDialog #points-picture { width: 64; height: 16; }
    PointsDialog #points-caption { height: 1; }
    """

    def __init__(
        self,
        request: UserInputRequested,
        watch: Callable[[str, Callable[[CameraImage], None]], Callable[[], None]] | None = None,
        widget_class: Any = None,
    ) -> None:
        super().__init__(request)
        self._watch = watch
        self._widget_class = widget_class
        self._stop_watching: Callable[[], None] | None = None
        self._image: CameraImage | None = None
        self._lock = threading.Lock()
        self._fresh: CameraImage | None = None

    def compose(self) -> ComposeResult:
        request = self.request
        with Vertical(classes="dialog wide"):
            yield from self.compose_title()
            yield Static(f"Waiting for an image on {request.image_topic} ...", id="points-caption")
            if self._widget_class is not None:
                picture = self._widget_class(id="points-picture")
                picture.display = False
                yield picture
            for index, prompt in enumerate(request.point_prompts):
                yield Label(f"{index + 1}. {prompt} (column row, pixels)")
                yield Input("", placeholder="click the image, or type e.g. 320 240", id=f"point-{index}")
            yield from self.compose_buttons()

    def on_mount(self) -> None:
        if self._watch is not None and self.request.image_topic:
            self.run_worker(self._start_watching, thread=True, group="points-image")
        self.set_interval(0.2, self._show_latest)

    def _start_watching(self) -> None:
        assert self._watch is not None
        try:
            self._stop_watching = self._watch(self.request.image_topic, self._receive)
        except Exception as error:  # shown, never raised: the runtime may be gone
            self.app.call_from_thread(self._caption, f"no image from {self.request.image_topic}: {error}")

    def _receive(self, image: CameraImage) -> None:
        with self._lock:
            if self._image is None:  # the first picture stays: the user clicks on a still image
                self._fresh = image

    def _show_latest(self) -> None:
        with self._lock:
            image, self._fresh = self._fresh, None
            if image is not None:
                self._image = image
        if image is None:
            return
        height, width = image.pixels.shape[:2]
        size = f"{width} x {height} pixels (column 0..{width - 1}, row 0..{height - 1})"
        self._caption(f"{image.topic}: {size}")
        for picture in self.query("#points-picture"):
            from PIL import Image as PilImage

            picture.image = PilImage.fromarray(image.pixels)  # type: ignore[attr-defined]
            picture.display = True
        if self._stop_watching is not None:
            self._stop_watching()  # one still image is enough; a simulated camera stops rendering
            self._stop_watching = None

    def _caption(self, text: str) -> None:
        self.query_one("#points-caption", Static).update(text)

    def on_click(self, event: Any) -> None:
        """A click on the picture fills the first empty point with the pixel under the pointer."""
        widget = getattr(event, "widget", None)
        if widget is None or widget.id != "points-picture" or self._image is None:
            return
        height, width = self._image.pixels.shape[:2]
        cells_x, cells_y = max(widget.size.width, 1), max(widget.size.height, 1)
        column = min(width - 1, int((event.x + 0.5) * width / cells_x))
        row = min(height - 1, int((event.y + 0.5) * height / cells_y))
        for field in self.query(Input):
            if not field.value.strip():
                field.value = f"{column} {row}"
                return
        self.notify("Every point is given; clear one to click it again.", severity="information")

    def _give(self) -> None:
        points: list[tuple[float, float]] = []
        for index, field in enumerate(self.query(Input)):
            try:
                column, row = _numbers(field.value, 2, f"Point {index + 1}")
            except ValueError as error:
                self.notify(str(error), severity="warning")
                field.focus()
                return
            points.append((column, row))
        self.dismiss(UserInputAnswer(True, points=tuple(points)))

    def on_unmount(self) -> None:
        if self._stop_watching is not None:
            self._stop_watching()
            self._stop_watching = None


class TeleoperateDialog(_UserInputDialog):
    """A teleoperation session: each button tells the running objective a mode (open or close the gripper,
    move to a target pose or to joint values, which then ask for them); Done ends the session, Cancel fails
    it."""

    BINDINGS = [
        Binding("ctrl+d", "done", "Done", id="dialog.done", tooltip="End it; the objective goes on"),
        Binding("escape", "cancel", "Cancel", id="dialog.cancel", tooltip="Stop: the objective fails"),
    ]
    MODES = (
        (TELEOP_TARGET_POSE, "Move to a pose", "teleop-pose"),
        (TELEOP_JOINT_VALUES, "Move to joint values", "teleop-joints"),
        (TELEOP_OPEN_GRIPPER, "Open gripper", "teleop-open"),
        (TELEOP_CLOSE_GRIPPER, "Close gripper", "teleop-close"),
    )

    def __init__(self, request: UserInputRequested, pick_mode: Callable[[int], None]) -> None:
        super().__init__(request)
        self._pick_mode = pick_mode
        self.mode = request.initial_teleop_mode

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog wide"):
            yield from self.compose_title()
            yield Label(self._mode_text(), id="teleop-mode", classes="dialog-keys")
            with Horizontal(classes="dialog-buttons"):
                for _mode, label, widget_id in self.MODES:
                    yield Button(label, id=widget_id)
            yield Label("ctrl+d: Done (the objective goes on)  Esc: Cancel (it fails)", classes="dialog-keys")
            with Horizontal(classes="dialog-buttons"):
                yield Button("Done (ctrl+d)", variant="success", id="done")
                yield Button("Cancel (Esc)", id="cancel")

    def _mode_text(self) -> str:
        names = {mode: label for mode, label, _id in self.MODES}
        return f"Mode: {names.get(self.mode, 'none')}"

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        if event.button.id == "done":
            self.action_done()
        elif event.button.id == "cancel":
            self.action_cancel()
        else:
            mode = next(mode for mode, _label, widget_id in self.MODES if widget_id == event.button.id)
            self.choose(mode)

    def choose(self, mode: int) -> None:
        """Pick ``mode``: the objective acts on it (a pose or joint values question follows for a move)."""
        self.mode = mode
        self.query_one("#teleop-mode", Label).update(self._mode_text())
        self._pick_mode(mode)

    def action_done(self) -> None:
        self.dismiss(UserInputAnswer(True, "done"))
