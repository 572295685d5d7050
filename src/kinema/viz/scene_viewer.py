"""The meshcat bridge: subscribes to the runtime and keeps the meshcat scene in step with it.

Inputs (all read-only subscriptions; the viewer never calls the runtime):

- ``/mujoco/scene_state`` (whole qpos, free objects included, 30 Hz of wall time) and ``/joint_states``
  (100 Hz of sim time): the robot and the objects, drawn at up to ``frame_rate`` Hz. Callbacks only keep
  the newest raw message; the frame thread decodes the newest one per frame. ``/joint_states`` is
  subscribed only while it is cheap and useful: when the driver has no scene state (a real robot), or when
  the simulation runs at about real time (it then adds updates between scene states). A simulation running
  many times faster than real time publishes thousands of joint states per second, and merely receiving
  them would slow it down, so the view then draws the 30 Hz scene state alone.
- ``/kinema/planned_trajectory``: the end effector's path along the planned trajectory (a line).
- ``/visualization_marker_array`` and ``/visualization_marker``: markers (VisualizePose's triads).
- the agent's heartbeat and ``/clock``: whether the runtime is there (a banner on the page when not).
"""

from __future__ import annotations

import logging
import threading
import time
import uuid
from typing import Any

import meshcat.geometry as g
import numpy as np

from kinema import ui_topics as topics
from kinema.drivers.mujoco import names as driver_names
from kinema.runtime import names as agent_names
from kinema.transforms import TransformError, pose_matrix
from kinema.transport import Node, Session
from kinema.viz import scene_commands as sc
from kinema.viz.liveness import RuntimeLiveness
from kinema.viz.markers import MarkerBoard
from kinema.viz.meshcat_server import Command, MeshcatServer
from kinema.viz.planning_scene import PlanningSceneLayer
from kinema.viz.scene_model import ROOT, SceneModel

log = logging.getLogger("kinema.viz")

PLANNED_PATH = f"{ROOT}/planned_path"
PLANNED_PATH_COLOR = 0xFF7F00
DEFAULT_FRAME_RATE = 60.0
# /joint_states is dropped while the sim runs faster than this many times real time (see the docstring).
JOINT_STATES_MAX_SIM_SPEED = 2.0
# Without a scene state for this long, the driver has none (a real robot): draw from /joint_states.
SCENE_STATE_ABSENT_S = 1.0


_ENDED = frozenset({"Success", "Failure", "Cancelled"})


class SceneViewer:
    """Draws a runtime's scene into a :class:`MeshcatServer` (see the module docstring).

    Args:
        session: the transport session to subscribe on.
        scene: the MuJoCo scene of the runtime's config.
        server: where to draw.
        endpoint: the router's endpoint (for messages on the page).
        config: the config package name (shown on the page).
        frame_rate: most frames per second sent to the page.
    """

    def __init__(
        self,
        session: Session,
        scene: SceneModel,
        server: MeshcatServer,
        *,
        endpoint: str = "",
        config: str = "",
        frame_rate: float = DEFAULT_FRAME_RATE,
    ) -> None:
        self.session = session
        self.scene = scene
        self.server = server
        self.config = config
        self.frame_rate = frame_rate
        self.liveness = RuntimeLiveness(endpoint or "the router")
        self.markers = MarkerBoard(f"{ROOT}/markers")
        self.planning_scene = PlanningSceneLayer(f"{ROOT}/planning_scene")
        self.server_id = uuid.uuid4().hex
        self.frames = 0
        self.state_updates = 0
        self._latest: dict[str, bytes | None] = {"scene": None, "joints": None}
        self._lock = threading.Lock()
        self._objective = ("", "")
        self._sim_time: float | None = None
        self._qpos_mismatch: int | None = None
        #: The config the runtime's agent says it runs (its presence), "" until heard; and why the view
        #: does not draw that one when it differs (set by the :class:`~kinema.viz.view.Viewer`).
        self.runtime_config = ""
        self.follow_note = ""
        self._was_lost = False
        self._rate_window: list[float] = []
        self._node: Node | None = None
        self._joint_states: Any = None
        # frames heard on /tf: child -> (parent, parent_T_child)
        self._tf: dict[str, tuple[str, np.ndarray]] = {}
        self._started_at = time.monotonic()
        self._last_scene: float | None = None
        # (wall, sim) of the first scene state of the current speed window, and the speed measured.
        self._speed_window: tuple[float, float] | None = None
        self._sim_speed: float | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._frames, name="kinema-viz-frames", daemon=True)

    # -- lifecycle -------------------------------------------------------------------------------------

    def start(self) -> None:
        """Draw the scene and start following the runtime."""
        self.server.send(self.scene.scene_commands())
        node = self._node = Node(self.session, "kinema_view")
        node.create_subscription(
            driver_names.SCENE_STATE_TYPE,
            driver_names.SCENE_STATE_TOPIC,
            self._keep("scene"),
            latched=True,
            raw=True,
        )
        node.create_subscription(agent_names.HEARTBEAT_TYPE, agent_names.HEARTBEAT, self._on_heartbeat)
        node.create_subscription(topics.MARKER_ARRAY_TYPE, topics.MARKER_ARRAY_TOPIC, self._on_marker_array)
        node.create_subscription(topics.MARKER_TYPE, topics.MARKER_TOPIC, self._on_marker)
        node.create_subscription(
            topics.PLANNED_TRAJECTORY_TYPE, topics.PLANNED_TRAJECTORY_TOPIC, self._on_planned_trajectory
        )
        node.create_subscription(
            agent_names.PLANNING_SCENE_TYPE, agent_names.PLANNING_SCENE, self._on_planning_scene, latched=True
        )
        node.create_subscription(topics.TF_TYPE, topics.TF_TOPIC, self._on_tf)
        self._thread.start()

    def stop(self) -> None:
        """Stop following (the server keeps serving what was drawn)."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=2.0)
        if self._node is not None:
            self._node.close()
            self._node = None

    # -- what the page reads -----------------------------------------------------------------------------

    def status(self) -> dict[str, Any]:
        """The JSON behind the page's banner and info line."""
        verdict = self.liveness.verdict()
        banner, level = verdict.banner, verdict.level
        if not banner and self.runtime_config and self.config and self.runtime_config != self.config:
            level = "warning"
            banner = self.follow_note or (
                f"The runtime runs config {self.runtime_config}; this view draws {self.config}."
            )
        if not banner and self._qpos_mismatch is not None:
            level = "warning"
            banner = (
                f"The simulation's state has {self._qpos_mismatch} qpos values but the scene drawn has "
                f"{self.scene.model.nq}: does the runtime run another config than "
                f"{self.config or 'this one'}?"
            )
        name, state = self._objective
        parts = [f"config {self.config}" if self.config else "Kinema"]
        if name or state:
            parts.append(f"objective {name or '-'}: {state or '-'}")
        if self._sim_time is not None:
            parts.append(f"sim time {self._sim_time:.1f} s")
        parts.append(f"{self.frame_rate_measured():.0f} updates/s")
        return {
            "server_id": self.server_id,
            "config": self.config,
            "level": level,
            "banner": banner,
            "info": " · ".join(parts),
            "frames": self.frames,
            "state_updates": self.state_updates,
            "objective": name,
            "objective_status": state,
        }

    def frame_rate_measured(self) -> float:
        """State updates drawn per second over the last second."""
        now = time.monotonic()
        with self._lock:
            recent = [t for t in self._rate_window if now - t <= 1.0]
        return float(len(recent))

    # -- subscriptions -----------------------------------------------------------------------------------

    def _keep(self, slot: str) -> Any:
        def keep(payload: bytes) -> None:
            self._latest[slot] = payload  # one reference swap: the frame thread decodes the newest only
            self.liveness.heard_driver()

        return keep

    def _follow_joint_states(self) -> None:
        """Subscribe to ``/joint_states`` or drop it, as the module docstring says."""
        now = time.monotonic()
        last_scene = self._last_scene
        no_scene = (last_scene is None and now - self._started_at > SCENE_STATE_ABSENT_S) or (
            last_scene is not None and now - last_scene > SCENE_STATE_ABSENT_S
        )
        slow_sim = self._sim_speed is not None and self._sim_speed <= JOINT_STATES_MAX_SIM_SPEED
        want = no_scene or slow_sim
        node = self._node
        if node is None:
            return
        if want and self._joint_states is None:
            self._joint_states = node.create_subscription(
                driver_names.JOINT_STATES_TYPE,
                driver_names.JOINT_STATES_TOPIC,
                self._keep("joints"),
                raw=True,
            )
        elif not want and self._joint_states is not None:
            self._joint_states.close()
            self._joint_states = None
            self._latest["joints"] = None

    def _measure_sim_speed(self, sim_time: float) -> None:
        wall = time.monotonic()
        self._last_scene = wall
        window = self._speed_window
        if window is None or sim_time < window[1]:
            self._speed_window = (wall, sim_time)  # first one, or the sim time went back (a new driver)
        elif wall - window[0] >= 1.0:
            self._sim_speed = (sim_time - window[1]) / (wall - window[0])
            self._speed_window = (wall, sim_time)

    def _on_heartbeat(self, message: Any) -> None:
        self.liveness.heard_heartbeat()
        name, state = str(message.objective_name), str(message.objective_status)
        previous_name, previous_state = self._objective
        if state == "Idle" and name == previous_name and previous_state in _ENDED:
            state = f"{previous_state} · idle"  # how the run ended stays on the page (the TUI does the same)
        elif state == "Idle" and name == previous_name and previous_state.endswith(" · idle"):
            state = previous_state
        self._objective = (name, state)

    def _on_marker_array(self, message: Any) -> None:
        for marker in message.markers:
            self._on_marker(marker)

    def _on_marker(self, marker: Any) -> None:
        frame_id = str(marker.header.frame_id)
        frame = self.frame_pose(frame_id)
        if frame is None:
            log.warning(
                "marker %s/%d: unknown frame %r; drawn in the world frame", marker.ns, marker.id, frame_id
            )
            frame = np.eye(4)
        self.server.send(self.markers.update(marker, frame))

    def _on_tf(self, message: Any) -> None:
        for transform in message.transforms:
            t, r = transform.transform.translation, transform.transform.rotation
            try:
                pose = pose_matrix([t.x, t.y, t.z], [r.x, r.y, r.z, r.w])
            except TransformError:
                continue
            self._tf[str(transform.child_frame_id)] = (str(transform.header.frame_id), pose)

    def frame_pose(self, frame_id: str, _depth: int = 0) -> np.ndarray | None:
        """World pose of a frame: a body of the scene, else a frame heard on ``/tf`` (PublishTF's), placed
        through its parent; None when neither knows it."""
        pose = self.scene.frame_pose(frame_id)
        if pose is not None or _depth > 8:
            return pose
        heard = self._tf.get(frame_id)
        if heard is None:
            return None
        parent = self.frame_pose(heard[0], _depth + 1)
        return None if parent is None else parent @ heard[1]

    def _on_planning_scene(self, message: Any) -> None:
        self.server.send(self.planning_scene.update(message, self.frame_pose))

    def _on_planned_trajectory(self, message: Any) -> None:
        positions = [list(point.positions) for point in message.points]
        if not positions:
            self.server.send([sc.delete(PLANNED_PATH)])
            return
        path = self.scene.tool_path(list(message.joint_names), positions)
        self.server.send(planned_path_commands(path))

    # -- frames ------------------------------------------------------------------------------------------

    def _frames(self) -> None:
        period = 1.0 / self.frame_rate
        next_frame = time.monotonic()
        while not self._stop.is_set():
            try:
                self.frame()
            except Exception:
                log.exception("drawing a frame failed")
            next_frame += period
            delay = next_frame - time.monotonic()
            if delay < 0:
                next_frame = time.monotonic()
                delay = 0.0
            self._stop.wait(delay)

    def frame(self) -> None:
        """Draw the newest state (if any arrived since the last frame), expire markers, follow liveness."""
        registry = self.session.registry
        commands: list[Command] = []
        scene_payload, self._latest["scene"] = self._latest["scene"], None
        joints_payload, self._latest["joints"] = self._latest["joints"], None
        changed = False
        if scene_payload is not None:
            state = registry.deserialize(scene_payload, driver_names.SCENE_STATE_TYPE)
            self._sim_time = state.stamp.sec + state.stamp.nanosec * 1e-9
            self._measure_sim_speed(self._sim_time)
            qpos = list(state.qpos)
            if self.scene.set_qpos(qpos):
                self._qpos_mismatch = None
                changed = True
            else:
                self._qpos_mismatch = len(qpos)
        if joints_payload is not None:
            joints = registry.deserialize(joints_payload, driver_names.JOINT_STATES_TYPE)
            changed = self.scene.set_joint_positions(list(joints.name), list(joints.position)) > 0 or changed
            if scene_payload is None and self._last_scene is None:
                self._sim_time = joints.header.stamp.sec + joints.header.stamp.nanosec * 1e-9
        if self.frames % 10 == 0:
            self._follow_joint_states()
        if changed:
            commands += self.scene.body_commands()
            commands += self.planning_scene.follow(self.frame_pose)
            now = time.monotonic()
            with self._lock:
                self._rate_window = [t for t in self._rate_window if now - t <= 1.0] + [now]
            self.state_updates += 1
        commands += self.markers.expire()
        lost = self.liveness.verdict().level == "error"
        if self._was_lost and not lost:
            # The runtime came back (a restart): what the old run planned and marked no longer applies.
            commands += self.markers.clear()
            commands.append(sc.delete(PLANNED_PATH))
        self._was_lost = lost
        if commands:
            self.server.send(commands)
        self.frames += 1


def planned_path_commands(points: np.ndarray) -> list[Command]:
    """Draw the tool path ``points`` (N, 3): a line, a dot at each end."""
    positions = np.asarray(points, dtype=np.float32)
    material = g.MeshPhongMaterial(color=PLANNED_PATH_COLOR)
    line = g.Line(g.PointsGeometry(positions.T), g.LineBasicMaterial(color=PLANNED_PATH_COLOR, linewidth=3))
    commands = [sc.delete(PLANNED_PATH), sc.set_object(f"{PLANNED_PATH}/line", line)]
    for name, point in (("start", positions[0]), ("goal", positions[-1])):
        placed = np.eye(4)
        placed[:3, 3] = point
        commands.append(sc.set_object(f"{PLANNED_PATH}/{name}", g.Mesh(g.Sphere(0.012), material)))
        commands.append(sc.set_transform(f"{PLANNED_PATH}/{name}", placed))
    return commands
