"""The camera view: the latest image of a topic drawn with half blocks (Pilot), and image conversion."""

from __future__ import annotations

import numpy as np
import pytest
from textual.widgets import Select, Static
from tui_pilot_harness import drive, settle

from kinema.errors import PerceptionError
from kinema.tui.fake_connection import FakeConnection
from kinema.tui.screens.camera import CameraScreen, image_widget_class


def picture(color: tuple[int, int, int], width: int = 64, height: int = 48) -> np.ndarray:
    pixels = np.zeros((height, width, 3), dtype=np.uint8)
    pixels[:, : width // 2] = color  # the left half coloured, the right half black
    return pixels


def drawn_colors(screen: CameraScreen) -> set[tuple[int, int, int]]:
    """The colours of the cells the picture widget draws (half blocks carry two colours a cell)."""
    picture = screen.query_one("#camera-picture")
    colors: set[tuple[int, int, int]] = set()
    for y in range(picture.content_region.height):
        for segment in picture.render_line(y):
            for color in (segment.style.color, segment.style.bgcolor) if segment.style else ():
                if color is not None and color.triplet is not None:
                    colors.add(tuple(color.triplet))
    return colors


def test_the_camera_view_shows_the_newest_image_of_the_chosen_topic(
    fake: FakeConnection, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("KINEMA_TUI_IMAGE", "halfcell")
    fake.cameras = {
        "/wrist_camera/color": picture((200, 30, 30)),
        "/scene_camera/color": picture((0, 0, 255)),
    }

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await pilot.press("7")
        await settle(pilot)
        screen = app.screen
        assert isinstance(screen, CameraScreen)
        select = screen.query_one("#camera-topic", Select)
        assert [value for _, value in select._options if isinstance(value, str)] == [
            "/scene_camera/color",
            "/wrist_camera/color",
        ]
        select.value = "/wrist_camera/color"
        await settle(pilot)
        await pilot.pause(0.5)  # the screen redraws every 0.2 s
        assert fake.called("watch_images") == [("/wrist_camera/color",)]
        caption = str(screen.query_one("#camera-caption", Static).render())
        assert "64x48 rgb8" in caption, caption
        assert (200, 30, 30) in drawn_colors(screen)
        # A newer frame replaces it.
        assert fake.push_image("/wrist_camera/color", picture((20, 220, 40)), stamp=1.5) == 1
        await pilot.pause(0.5)
        colors = drawn_colors(screen)
        assert (20, 220, 40) in colors and (200, 30, 30) not in colors, colors
        assert "t=1.50 s" in str(screen.query_one("#camera-caption", Static).render())
        # Another topic: the first is no longer watched (a simulated camera stops rendering).
        select.value = "/scene_camera/color"
        await settle(pilot)
        await pilot.pause(0.5)
        assert fake.called("stop_watching_images") == [("/wrist_camera/color",)]
        assert (0, 0, 255) in drawn_colors(screen)
        await pilot.press("escape")
        await settle(pilot)
        assert not isinstance(app.screen, CameraScreen)
        assert fake.called("stop_watching_images")[-1] == ("/scene_camera/color",)

    drive(fake, scenario)


def test_no_image_topic_is_said(fake: FakeConnection, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("KINEMA_TUI_IMAGE", "halfcell")
    fake.cameras = {}

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        await pilot.press("7")
        await settle(pilot)
        text = str(app.screen.query_one("#camera-placeholder", Static).render())
        assert "No image topic now" in text, text

    drive(fake, scenario)


def test_a_bad_drawing_method_names_the_valid_ones() -> None:
    with pytest.raises(ValueError, match="valid: auto, sixel, tgp, halfcell, unicode"):
        image_widget_class("ascii")


def test_depth_and_grey_images_become_rgb() -> None:
    from kinema.transport import from_dict
    from kinema.tui.camera_image import camera_image

    depth = np.array([[0.5, 1.0], [np.nan, 2.0]], dtype="<f4")
    message = from_dict(
        "sensor_msgs/msg/Image",
        {
            "header": {"frame_id": "cam", "stamp": {"sec": 3, "nanosec": 500000000}},
            "height": 2,
            "width": 2,
            "encoding": "32FC1",
            "step": 8,
            "data": np.frombuffer(depth.tobytes(), dtype=np.uint8),
        },
    )
    image = camera_image("/cam/depth", message)
    assert image.pixels.shape == (2, 2, 3) and image.stamp == 3.5 and image.frame_id == "cam"
    grey = image.pixels[:, :, 0]
    assert grey[0, 0] == 255 and grey[0, 0] > grey[0, 1] > grey[1, 1] > 0 and grey[1, 0] == 0
    bad = from_dict(
        "sensor_msgs/msg/Image",
        {"height": 1, "width": 1, "encoding": "yuv422", "step": 2, "data": np.zeros(2, dtype=np.uint8)},
    )
    with pytest.raises(PerceptionError, match="cannot show image encoding 'yuv422'; valid: rgb8"):
        camera_image("/cam/odd", bad)


def test_a_camera_asked_for_at_start_is_shown_once_the_runtime_connects(
    fake: FakeConnection, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`kinema ui --camera TOPIC` opens the view before the connection is up: it waits, then watches."""
    from kinema.tui.connection import ConnectionChanged, ConnectionState

    monkeypatch.setenv("KINEMA_TUI_IMAGE", "halfcell")
    fake.cameras = {"/wrist_camera/color": picture((200, 30, 30))}
    fake.connect_on_open = False

    async def scenario(app, pilot) -> None:  # type: ignore[no-untyped-def]
        screen = app.screen
        assert isinstance(screen, CameraScreen)
        assert not fake.called("watch_images")
        fake.emit(ConnectionChanged(ConnectionState.CONNECTED, fake.fake_endpoint))
        await pilot.pause(1.0)
        await settle(pilot)
        assert fake.called("watch_images")[-1] == ("/wrist_camera/color",)
        await pilot.pause(0.5)  # the screen redraws every 0.2 s
        assert (200, 30, 30) in drawn_colors(screen)

    drive(fake, scenario, camera="/wrist_camera/color")
