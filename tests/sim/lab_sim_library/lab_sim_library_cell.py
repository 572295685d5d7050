"""The running cell the lab_sim library tests talk to (its own module: tests import it by name)."""

from __future__ import annotations

import functools
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any


@functools.cache
def lab_sim_model() -> Any:
    """lab_sim's robot model (URDF, SRDF), loaded once."""
    from kinema.motion import RobotDescription

    return RobotDescription.lab_sim().load_model()


# The arm's joints (rail first), as MoveIt Pro's files list them: lab_sim's "manipulator" group.
ARM: tuple[str, ...] = tuple(lab_sim_model().group("manipulator").joint_names)


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
