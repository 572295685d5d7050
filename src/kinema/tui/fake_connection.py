"""A scripted :class:`~kinema.tui.connection.RuntimeConnection`: no runtime, no network, fully deterministic.

Tests, snapshot tests and the benchmark drive the app with it: they give it objectives, waypoints and
behaviors, push events with :meth:`FakeConnection.emit` as the runtime would, and read back what the app
asked for from :attr:`FakeConnection.calls`. ``kinema ui --demo`` shows the app on
:meth:`FakeConnection.demo`.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from kinema.errors import KinemaError, ObjectiveError, TransportError
from kinema.tui.connection import (
    BehaviorSummary,
    CameraImage,
    ConnectionChanged,
    ConnectionState,
    EventListener,
    Heartbeat,
    ImageListener,
    ObjectiveSummary,
    PortSummary,
    RuntimeEvent,
    WaypointSummary,
)

if TYPE_CHECKING:
    from kinema.config import Workspace


@dataclass
class FakeConnection:
    """A runtime stand-in.

    Attributes:
        objectives: what :meth:`list_objectives` returns.
        xml: objective name -> its XML document.
        waypoints: the waypoint list that save/rename/erase edit.
        behaviors: what :meth:`list_behaviors` returns.
        failures: method name -> the error that method raises (to test error display).
        calls: ``(method, args...)`` of every call the app made, in order.
        current_joints: what :meth:`save_waypoint` records.
        delay: seconds every call to the runtime takes (a slow or loaded runtime).
        cameras: image topic -> the picture a new watcher gets first (HxWx3 uint8), as a camera that
            renders on demand sends one; :meth:`push_image` sends more.
    """

    objectives: list[ObjectiveSummary] = field(default_factory=list)
    xml: dict[str, str] = field(default_factory=dict)
    waypoints: list[WaypointSummary] = field(default_factory=list)
    behaviors: list[BehaviorSummary] = field(default_factory=list)
    failures: dict[str, KinemaError] = field(default_factory=dict)
    calls: list[tuple[object, ...]] = field(default_factory=list)
    current_joints: tuple[tuple[str, float], ...] = (("joint_1", 0.0), ("joint_2", 0.5))
    fake_endpoint: str = "fake://runtime"
    fake_config: str | None = None
    workspace_root: str | None = None
    connect_on_open: bool = True
    connected: bool = False
    listener: EventListener | None = None
    cameras: dict[str, object] = field(default_factory=dict)
    delay: float = 0.0
    image_watchers: dict[str, list[ImageListener]] = field(default_factory=dict)
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    # -- the RuntimeConnection interface --------------------------------------------------------

    @property
    def endpoint(self) -> str:
        return self.fake_endpoint

    @property
    def config_name(self) -> str | None:
        return self.fake_config

    def open(self, listener: EventListener) -> None:
        self.listener = listener
        self._record("open")
        if self.connect_on_open:
            self.emit(ConnectionChanged(ConnectionState.CONNECTED, self.fake_endpoint))
            self.emit(Heartbeat(0.0, "", "Idle"))

    def close(self) -> None:
        self._record("close")
        self.listener = None

    def workspace(self) -> Workspace:
        from kinema.config import Workspace

        if self.workspace_root is None:
            return Workspace.bundled_only()
        return Workspace.discover(self.workspace_root)

    def list_objectives(self) -> list[ObjectiveSummary]:
        self._record("list_objectives")
        return list(self.objectives)

    def objective_xml(self, name: str) -> str:
        self._record("objective_xml", name)
        if name not in self.xml:
            raise ObjectiveError(f"no objective named {name!r}")
        return self.xml[name]

    def start_objective(self, name: str, overrides: Mapping[str, str]) -> None:
        self._record("start_objective", name, dict(overrides))

    def cancel_objective(self) -> None:
        self._record("cancel_objective")

    def list_waypoints(self) -> list[WaypointSummary]:
        self._record("list_waypoints")
        return list(self.waypoints)

    def move_to_waypoint(self, name: str) -> None:
        self._record("move_to_waypoint", name)

    def save_waypoint(self, name: str, joint_group_names: tuple[str, ...] = ()) -> WaypointSummary:
        self._record("save_waypoint", name)
        names, positions = zip(*self.current_joints, strict=True) if self.current_joints else ((), ())
        waypoint = WaypointSummary(name, joint_names=tuple(names), positions=tuple(positions))
        self.waypoints = [w for w in self.waypoints if w.name != name] + [waypoint]
        return waypoint

    def rename_waypoint(self, name: str, new_name: str) -> None:
        self._record("rename_waypoint", name, new_name)
        if not any(w.name == name for w in self.waypoints):
            raise KinemaError(f"no waypoint named {name!r}")
        self.waypoints = [replace(w, name=new_name) if w.name == name else w for w in self.waypoints]

    def erase_waypoint(self, name: str) -> None:
        self._record("erase_waypoint", name)
        self.waypoints = [w for w in self.waypoints if w.name != name]

    def list_behaviors(self) -> list[BehaviorSummary]:
        self._record("list_behaviors")
        return list(self.behaviors)

    def image_topics(self) -> list[str]:
        self._record("image_topics")
        self._require_connected()
        return sorted(self.cameras)

    def watch_images(self, topic: str, listener: ImageListener) -> Callable[[], None]:
        self._record("watch_images", topic)
        self._require_connected()
        with self._lock:
            self.image_watchers.setdefault(topic, []).append(listener)
        first = self.cameras.get(topic)
        if first is not None:
            listener(CameraImage(topic, first, "rgb8", "camera_optical_frame", 0.0))

        def stop() -> None:
            self._record("stop_watching_images", topic)
            with self._lock:
                watchers = self.image_watchers.get(topic, [])
                if listener in watchers:
                    watchers.remove(listener)

        return stop

    def set_teleoperation_mode(self, mode: int) -> None:
        self._record("set_teleoperation_mode", mode)

    # -- driving it -----------------------------------------------------------------------------

    def _require_connected(self) -> None:
        """Refuse as the real connection does before it has a runtime."""
        if not self.connected:
            raise TransportError(f"not connected to a runtime at {self.fake_endpoint} (fake)")

    def emit(self, event: RuntimeEvent) -> None:
        """Deliver ``event`` as the runtime would (on the calling thread)."""
        if isinstance(event, ConnectionChanged):
            self.connected = event.state is ConnectionState.CONNECTED
        listener = self.listener
        if listener is not None:
            listener(event)

    def push_image(self, topic: str, pixels: object, stamp: float = 0.0) -> int:
        """Send a picture (HxWx3 uint8) to everyone watching ``topic``; returns how many watch it."""
        with self._lock:
            watchers = list(self.image_watchers.get(topic, []))
        for listener in watchers:
            listener(CameraImage(topic, pixels, "rgb8", "camera_optical_frame", stamp))
        return len(watchers)

    def called(self, method: str) -> list[tuple[object, ...]]:
        """The argument tuples of every call of ``method``."""
        with self._lock:
            return [call[1:] for call in self.calls if call[0] == method]

    def _record(self, method: str, *args: object) -> None:
        with self._lock:
            self.calls.append((method, *args))
        if self.delay and method not in ("open", "close"):
            time.sleep(self.delay)  # a slow runtime: the app calls it off the UI thread
        failure = self.failures.get(method)
        if failure is not None:
            raise failure

    # -- a ready-made runtime -------------------------------------------------------------------

    @classmethod
    def demo(cls) -> FakeConnection:
        """A small, fixed library: two objectives (one with a subtree and ports), waypoints, behaviors."""
        pick_ports = (
            PortSummary(
                "waypoint_name", "input", "Look at Table", "Where to look before picking", "std::string"
            ),
            PortSummary("speed", "input", "0.5", "Velocity scale factor", "double"),
            PortSummary("grasp_pose", "output", "{grasp_pose}", "The pose that was picked"),
        )
        objectives = [
            ObjectiveSummary(
                "Pick Object",
                "Look at the table, pick the closest object and report where it was.",
                "Application - Basic Examples",
                True,
                True,
                "lab_sim",
                "objectives/pick_object.xml",
                pick_ports,
            ),
            ObjectiveSummary(
                "Open Gripper",
                "Open the gripper fully.",
                "Grasping",
                True,
                False,
                "lab_sim",
                "objectives/open_gripper.xml",
            ),
            ObjectiveSummary(
                "Wait and Log",
                "A subtree that waits and logs.",
                "Utilities",
                False,
                False,
                "kinema_objectives",
                "objectives/wait_and_log.xml",
                (PortSummary("seconds", "input", "1.0", "How long to wait"),),
            ),
        ]
        xml = {
            "Pick Object": _PICK_XML,
            "Open Gripper": _OPEN_XML,
            "Wait and Log": _WAIT_XML,
        }
        waypoints = [
            WaypointSummary("Home", "Arm up, out of the way", True, ("joint_1", "joint_2"), (0.0, 0.0)),
            WaypointSummary("Look at Table", "", False, ("joint_1", "joint_2"), (0.3, -1.2)),
        ]
        behaviors = [
            BehaviorSummary(
                "MoveToWaypoint",
                "kinema_core",
                "bundled: plugins/core",
                "plugins/core/motion.py:41",
                (
                    PortSummary("waypoint_name", "input", "", "The saved waypoint to move to", "str"),
                    PortSummary("velocity_scale_factor", "input", "1.0", "Fraction of max speed", "float"),
                ),
                {"subcategory": "Motion - Execute", "description": "Plan and move to a saved waypoint."},
            ),
            BehaviorSummary(
                "MyBehavior",
                "examples",
                "workspace: src/my_behaviors",
                "src/my_behaviors/my_behavior.py:12",
                (
                    PortSummary("int_1", "input", "0", "First addend", "int"),
                    PortSummary("int_2", "input", "0", "Second addend", "int"),
                    PortSummary("int_out", "output", "{int_out}", "The sum", "int"),
                ),
                {"subcategory": "Examples", "description": "Adds two integers."},
            ),
        ]
        return cls(
            objectives=objectives,
            xml=xml,
            waypoints=waypoints,
            behaviors=behaviors,
            fake_config="lab_sim",
            cameras={"/wrist_camera/color": demo_picture()},
        )


def demo_picture(width: int = 64, height: int = 48) -> object:
    """A small made-up camera picture: a grey-blue gradient (the table) with a red square (the cube)."""
    import numpy as np

    rows = np.linspace(90, 200, height, dtype=np.float32)[:, None]
    pixels = np.empty((height, width, 3), dtype=np.uint8)
    pixels[:, :, 0] = rows * 0.8
    pixels[:, :, 1] = rows * 0.85
    pixels[:, :, 2] = rows
    y, x = height // 3, width // 2
    pixels[y : y + height // 4, x : x + height // 4] = (200, 30, 30)
    return pixels


_PICK_XML = """<?xml version="1.0" encoding="UTF-8"?>
<root BTCPP_format="4" main_tree_to_execute="Pick Object">
  <BehaviorTree ID="Pick Object" _description="Look at the table, pick the closest object" _favorite="true">
    <Sequence name="TopLevelSequence">
      <Action ID="MoveToWaypoint" waypoint_name="{waypoint_name}" velocity_scale_factor="{speed}"/>
      <SubTree ID="Wait and Log" seconds="0.5"/>
      <Fallback>
        <Action ID="AlwaysFailure"/>
        <Action ID="Script" code="grasp_pose := 'on the table'"/>
      </Fallback>
    </Sequence>
  </BehaviorTree>
</root>
"""

_OPEN_XML = """<?xml version="1.0" encoding="UTF-8"?>
<root BTCPP_format="4" main_tree_to_execute="Open Gripper">
  <BehaviorTree ID="Open Gripper">
    <Action ID="AlwaysSuccess" name="OpenGripper"/>
  </BehaviorTree>
</root>
"""

_WAIT_XML = """<?xml version="1.0" encoding="UTF-8"?>
<root BTCPP_format="4" main_tree_to_execute="Wait and Log">
  <BehaviorTree ID="Wait and Log" _subtreeOnly="true">
    <Sequence>
      <Sleep msec="500"/>
      <Action ID="LogMessage" message="waited"/>
    </Sequence>
  </BehaviorTree>
</root>
"""
