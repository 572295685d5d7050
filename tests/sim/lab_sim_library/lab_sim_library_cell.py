"""The running cell the lab_sim library tests talk to (its own module: tests import it by name)."""

from __future__ import annotations

import functools
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest


@functools.cache
def lab_sim_model() -> Any:
    """lab_sim's robot model (URDF, SRDF), loaded once."""
    from kinema.motion import RobotDescription

    return RobotDescription.lab_sim().load_model()


# The arm's joints (rail first), as MoveIt Pro's files list them: lab_sim's "manipulator" group.
ARM: tuple[str, ...] = tuple(lab_sim_model().group("manipulator").joint_names)


def wait_for(predicate: Callable[[], Any], timeout: float, what: str) -> Any:
    """The first true value of ``predicate`` within ``timeout`` s, else an AssertionError naming ``what``."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.02)
    raise AssertionError(f"timed out after {timeout} s waiting for {what}")


@dataclass
class LibraryCell:
    """A running lab_sim cell whose lab_sim objectives are MoveIt Pro's."""

    client: Any
    node: Any
    objectives: Path
    driver: Any = None  # the in-process MujocoDriver, for checks against the simulated geometry
    endpoint: str = ""
    _topics: dict[str, list[Any]] = field(default_factory=dict)
    _lock: threading.Lock = field(default_factory=threading.Lock)

    def listen(self, msg_type: str, topic: str, *, latched: bool = False) -> list[Any]:
        """Keep every message on ``topic`` from now on; the list fills as they arrive."""
        with self._lock:
            if topic not in self._topics:
                box: list[Any] = []
                self._topics[topic] = box
                self.node.create_subscription(msg_type, topic, box.append, latched=latched)
            return self._topics[topic]

    def render_each_camera_once(self, topics: tuple[tuple[str, str], ...], timeout: float) -> None:
        """Skip (naming what to install) without OpenGL; else take one message of each (type, topic).

        The objectives give a camera 5-10 s; in this one process (driver, agent and test side by side on a
        loaded machine) a camera's first frame after a subscription can take longer. Unwatched again
        afterwards, the cameras stop rendering.
        """
        from kinema.drivers.mujoco.cameras import GL_HELP

        cameras = self.driver.cameras
        assert cameras is not None, "lab_sim has cameras, the driver serves none"
        assert cameras.ready.wait(60), "the camera thread did not get ready within 60 s"
        if cameras.unavailable is not None:
            pytest.skip(f"no OpenGL for MuJoCo ({cameras.unavailable}). {GL_HELP}")
        for msg_type, topic in topics:
            box: list[Any] = []
            subscription = self.node.create_subscription(msg_type, topic, box.append)
            try:
                wait_for(lambda: box, timeout, f"a first message on {topic}")  # noqa: B023 - called now
            finally:
                subscription.close()
