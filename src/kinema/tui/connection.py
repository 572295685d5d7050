"""The TUI's view of a runtime: one small adapter interface, the values it returns and the events it sends.

The app never talks to the transport or the SDK directly. It holds a :class:`RuntimeConnection`, calls
its blocking methods from worker threads, and receives :data:`RuntimeEvent` values from it on any thread.
Two implementations exist: :class:`kinema.tui.sdk_connection.SdkConnection` (a real runtime, through
:mod:`kinema.sdk`) and :class:`kinema.tui.fake_connection.FakeConnection` (scripted, for tests, snapshots
and benchmarks). Nothing here imports textual, so this module is testable on its own.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from kinema.config import Workspace


class ConnectionState(enum.StrEnum):
    """Whether the runtime answers."""

    CONNECTING = "connecting"
    CONNECTED = "connected"
    DISCONNECTED = "disconnected"


class NodeStatus(enum.IntEnum):
    """A behavior tree node's status as ``kinema_msgs/NodeStatusChange`` numbers it."""

    IDLE = 0
    RUNNING = 1
    SUCCESS = 2
    FAILURE = 3
    SKIPPED = 4


class LogLevel(enum.IntEnum):
    """``moveit_studio_agent_msgs/Log`` levels (lower is more severe), plus DEBUG for local messages."""

    ERROR = 1
    WARN = 2
    INFO = 3
    DEBUG = 4


@dataclass(frozen=True)
class PortSummary:
    """A port of an objective (its subtree interface) or of a behavior.

    Attributes:
        name: the port name.
        direction: ``"input"``, ``"output"`` or ``"inout"``.
        default: the default as written (``{key}`` for a blackboard default), "" when none.
        description: one line for a person.
        type_name: the value type when known (behaviors), "" otherwise.
    """

    name: str
    direction: str
    default: str = ""
    description: str = ""
    type_name: str = ""


@dataclass(frozen=True)
class ObjectiveSummary:
    """An objective of the runtime's library (``kinema_msgs/ObjectiveInfo``)."""

    name: str
    description: str = ""
    subcategory: str = ""
    runnable: bool = True
    favorite: bool = False
    package: str = ""
    file_path: str = ""
    ports: tuple[PortSummary, ...] = ()


@dataclass(frozen=True)
class WaypointSummary:
    """A saved waypoint (``moveit_studio_agent_msgs/Waypoint``)."""

    name: str
    description: str = ""
    favorite: bool = False
    joint_names: tuple[str, ...] = ()
    positions: tuple[float, ...] = ()
    joint_group_names: tuple[str, ...] = ()


@dataclass(frozen=True)
class BehaviorSummary:
    """A behavior of the registry: what objectives can use as ``<Action ID=...>``.

    Attributes:
        id: the behavior ID.
        plugin: the plugin (loader name) that registered it.
        source: where the plugin came from (``bundled``, ``entry point``, ``workspace``) and its path.
        location: ``file:line`` of the class.
        ports: the behavior's ports.
        metadata: subcategory, description, ...
    """

    id: str
    plugin: str = ""
    source: str = ""
    location: str = ""
    ports: tuple[PortSummary, ...] = ()
    metadata: Mapping[str, str] = field(default_factory=dict)


# --- events: what a connection reports, on any thread -----------------------------------------


@dataclass(frozen=True)
class ConnectionChanged:
    """The runtime started or stopped answering. ``detail`` says why, for a person."""

    state: ConnectionState
    endpoint: str
    detail: str = ""


@dataclass(frozen=True)
class Heartbeat:
    """One ``/objective_server_heartbeat``: the server's process time, objective and status.

    ``warnings`` are the watchdog's (``/objective_server/health``, published with each heartbeat):
    behavior code stuck in a tick, tick threads abandoned or dead; empty when all is well.
    """

    process_time: float
    objective_name: str
    status: str
    warnings: tuple[str, ...] = ()


@dataclass(frozen=True)
class NodeStatusUpdate:
    """One node of the running tree changed status."""

    uid: int
    node_path: str
    node_id: str
    node_name: str
    status: NodeStatus
    previous: NodeStatus = NodeStatus.IDLE


@dataclass(frozen=True)
class NodeStatusBatch:
    """The node status changes of one tick of ``objective_name``."""

    objective_name: str
    updates: tuple[NodeStatusUpdate, ...]


@dataclass(frozen=True)
class BlackboardEntry:
    """One blackboard entry; ``scope`` is the subtree path ("" for the root blackboard)."""

    scope: str
    key: str
    type_name: str
    value: str


@dataclass(frozen=True)
class BlackboardSnapshot:
    """Every blackboard entry of the running (or last) objective, at ``stamp`` (seconds)."""

    objective_name: str
    stamp: float
    entries: tuple[BlackboardEntry, ...]


@dataclass(frozen=True)
class LogEntry:
    """A log message or behavior toast (``publish_info/warn/failure``)."""

    message: str
    level: LogLevel = LogLevel.INFO
    stamp: float = 0.0
    source: str = ""


@dataclass(frozen=True)
class ClockSample:
    """Simulation time from ``/clock`` and the real-time factor measured over the last window."""

    sim_time: float
    real_time_factor: float | None = None


@dataclass(frozen=True)
class ReloadNotice:
    """A hot reload happened (or failed). ``location`` is ``file:line`` for failures."""

    ok: bool
    kind: str
    subject: str
    message: str
    location: str = ""
    behaviors: tuple[str, ...] = ()
    stamp: float = 0.0


@dataclass(frozen=True)
class ObjectivesChanged:
    """The runtime's objective library changed (an objective file was saved): list it again."""


@dataclass(frozen=True)
class TaskStage:
    """A stage of a task being planned (``kinema_msgs/TaskStageStatus``).

    Attributes:
        name: the stage's name (``connect``, ``approach``).
        type: its type (``MoveAlongFrameAxis``).
        kind: ``generator``, ``propagator`` or ``connector``.
        state: ``waiting``, ``planning``, ``solved`` or ``failed``.
        seconds: time spent planning it so far.
        comment: why it failed, or how a candidate fared.
    """

    name: str
    type: str = ""
    kind: str = ""
    state: str = "waiting"
    seconds: float = 0.0
    comment: str = ""


@dataclass(frozen=True)
class TaskPlanning:
    """The task PlanMTCTask plans, stage by stage (``/kinema/task_planning``); the newest replaces the last.

    Attributes:
        task_id: the task's id.
        node_path: the PlanMTCTask node planning it.
        state: ``planning``, ``solved`` or ``failed``.
        seconds: since planning started.
        message: why it failed ("" otherwise).
        stages: the stages, in order.
    """

    task_id: str
    node_path: str
    state: str
    seconds: float
    message: str = ""
    stages: tuple[TaskStage, ...] = ()


@dataclass(frozen=True)
class SolutionStep:
    """One motion of a solution shown for approval (``kinema_msgs/SolutionStep``).

    Attributes:
        stage: the stage that planned it.
        duration: seconds.
        joint_names: the joints it moves.
        gripper: what the gripper does during it ("" when it holds still).
        note: for a change between motions (collision rules) instead of a motion, what changed.
    """

    stage: str
    duration: float
    joint_names: tuple[str, ...] = ()
    gripper: str = ""
    note: str = ""


@dataclass(frozen=True)
class ApprovalRequested:
    """A behavior asks the user (WaitForMTCSolutionApproval, BreakpointSubscriber) and waits for the answer.

    Attributes:
        prompt: the question.
        behavior: the behavior ID that asks.
        node_path: its node in the running tree.
        answer: call once with ``(approved, message)``; any thread.
        steps: the planned motion being approved, motion by motion (empty when it is not a motion).
        duration: the whole motion's duration, seconds.
    """

    prompt: str
    behavior: str
    node_path: str
    answer: Callable[[bool, str], None] = field(compare=False, repr=False)
    steps: tuple[SolutionStep, ...] = ()
    duration: float = 0.0


@dataclass(frozen=True)
class UserInputAnswer:
    """The user's answer to a :class:`UserInputRequested`.

    Attributes:
        accepted: False when the user cancelled.
        message: what the user said, if anything.
        frame_id: the pose's frame (a pose answer).
        position: the pose's position, m (a pose answer).
        orientation: the pose's orientation quaternion, x y z w (a pose answer).
        points: one pixel (column, row) per point prompt (a points answer).
        joint_positions: a value per joint of the request's ``joint_names``, in order (a joint state
            answer).
    """

    accepted: bool
    message: str = ""
    frame_id: str = "world"
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    orientation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)
    points: tuple[tuple[float, float], ...] = ()
    joint_positions: tuple[float, ...] = ()


@dataclass(frozen=True)
class UserInputRequested:
    """A behavior asks the user for a value and waits (``kinema_msgs/srv/RequestUserInput``).

    ``kind`` is ``pose`` (RetrievePoseParameter: a target pose; ``frame_id``, ``position`` and
    ``orientation`` are where the tool is now), ``joint_state`` (RetrieveRobotStateParameter: a value per
    joint of ``joint_names``; ``joint_positions`` are where they are now), ``points`` (GetPointsFromUser: one
    pixel per entry of ``point_prompts`` on ``image_topic``) or ``teleoperate`` (DoTeleoperateAction: a
    session the user ends; the modes they pick go to :meth:`RuntimeConnection.set_teleoperation_mode`).

    Attributes:
        kind: what is asked.
        prompt: the question.
        behavior: the behavior ID that asks.
        node_path: its node in the running tree.
        answer: call once with a :class:`UserInputAnswer`; any thread.
    """

    kind: str
    prompt: str
    behavior: str
    node_path: str
    answer: Callable[[UserInputAnswer], None] = field(compare=False, repr=False)
    frame_id: str = "world"
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    orientation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)
    image_topic: str = ""
    point_prompts: tuple[str, ...] = ()
    point_names: tuple[str, ...] = ()
    initial_teleop_mode: int = 0
    joint_names: tuple[str, ...] = ()
    joint_positions: tuple[float, ...] = ()


# moveit_studio_sdk_msgs/TeleoperationMode values the TUI offers.
TELEOP_TARGET_POSE = 4
TELEOP_JOINT_VALUES = 5  # MoveIt Pro's joint sliders
TELEOP_OPEN_GRIPPER = 6
TELEOP_CLOSE_GRIPPER = 7
TELEOP_NONE = 0


@dataclass(frozen=True)
class CameraImage:
    """One picture of an image topic, ready to show.

    Attributes:
        topic: the topic it came on.
        pixels: HxWx3 uint8 RGB (depth images are shaded grey: near is light).
        encoding: the message's encoding (``rgb8``, ``32FC1``, ...).
        frame_id: the camera frame.
        stamp: the message's time (s; sim time for the simulated cameras).
    """

    topic: str
    pixels: Any
    encoding: str = "rgb8"
    frame_id: str = ""
    stamp: float = 0.0


ImageListener = Callable[[CameraImage], None]


RuntimeEvent = (
    ConnectionChanged
    | Heartbeat
    | NodeStatusBatch
    | BlackboardSnapshot
    | LogEntry
    | ClockSample
    | ReloadNotice
    | ObjectivesChanged
    | ApprovalRequested
    | UserInputRequested
    | TaskPlanning
)
EventListener = Callable[[RuntimeEvent], None]


class RuntimeConnection(Protocol):
    """What the TUI needs from a runtime. Blocking methods run on worker threads, never on the UI thread.

    Every method that talks to the runtime raises :class:`kinema.errors.KinemaError` (usually a
    ``TransportError`` or ``ObjectiveError``) with a message for a person when it fails; the app shows
    the message and keeps running.
    """

    @property
    def endpoint(self) -> str:
        """Where the runtime is (``tcp/127.0.0.1:7447``), for the status bar."""

    @property
    def config_name(self) -> str | None:
        """The config package the runtime runs (preselected in the Configs screen), if known."""

    def open(self, listener: EventListener) -> None:
        """Start receiving events; returns at once. Reconnects on its own while open.

        ``listener`` is called on background threads and must not block.
        """

    def close(self) -> None:
        """Stop receiving events and release the session (does not stop the runtime)."""

    def workspace(self) -> Workspace:
        """The workspace whose config packages the Configs screen browses."""

    def list_objectives(self) -> list[ObjectiveSummary]:
        """The runtime's objective library."""

    def objective_xml(self, name: str) -> str:
        """The BT.CPP v4 XML document that defines objective ``name``."""

    def start_objective(self, name: str, overrides: Mapping[str, str]) -> None:
        """Start objective ``name`` with overrides (port name -> YAML text); returns once accepted."""

    def cancel_objective(self) -> None:
        """Cancel whatever objective runs."""

    def list_waypoints(self) -> list[WaypointSummary]:
        """The saved waypoints."""

    def move_to_waypoint(self, name: str) -> None:
        """Start moving the robot to waypoint ``name``."""

    def save_waypoint(self, name: str, joint_group_names: tuple[str, ...] = ()) -> WaypointSummary:
        """Save the robot's current joint state as waypoint ``name``."""

    def rename_waypoint(self, name: str, new_name: str) -> None:
        """Rename waypoint ``name`` to ``new_name``."""

    def erase_waypoint(self, name: str) -> None:
        """Delete waypoint ``name``."""

    def list_behaviors(self) -> list[BehaviorSummary]:
        """The behaviors the runtime's config can use."""

    def image_topics(self) -> list[str]:
        """The topics that carry ``sensor_msgs/Image`` now (camera colour and depth streams)."""

    def watch_images(self, topic: str, listener: ImageListener) -> Callable[[], None]:
        """Call ``listener`` with each image on ``topic`` (on background threads; it must not block).

        Returns the function that stops watching. A simulated camera renders only while watched.
        """

    def set_teleoperation_mode(self, mode: int) -> None:
        """Tell the running teleoperation session (DoTeleoperateAction) the mode the user picked."""
