"""The scene's cameras, rendered offscreen and served only while someone listens.

Each MuJoCo ``<camera>`` becomes four topics (names in :mod:`kinema.drivers.mujoco.names`):
``/<camera>/color`` (``rgb8`` Image), ``/<camera>/depth`` (``32FC1`` Image, metres along the optical
axis, NaN where nothing was hit), ``/<camera>/camera_info`` and ``/<camera>/points`` (an organised
PointCloud2 with colours). Everything is stamped with the sim time of the state it shows and expressed in
the frame of the body that holds the camera (lab_sim's ``<camera>_optical_frame`` links, z forward,
x right, y down).

Rendering never runs on the physics thread: a camera thread polls which streams have subscribers; when
one does and the camera is due (at most ``rate`` per wall second), it asks the physics thread for a copy
of the state (a few microseconds between two steps), poses its own ``MjData`` there and renders with its
own OpenGL context. Nobody subscribed means nothing rendered, so a simulation nobody watches runs as fast
as without cameras.

OpenGL: headless, MuJoCo renders through EGL (``MUJOCO_GL=egl``, set by :mod:`kinema.drivers.mujoco`
when there is no display and libEGL loads; ``disable`` when it does not, since ``import mujoco`` fails
with a backend whose library is missing) or OSMesa (``MUJOCO_GL=osmesa``). When no context can be made,
the driver runs on without cameras and logs why and the packages to install (:data:`GL_HELP`).
"""

from __future__ import annotations

import logging
import math
import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

import kinema.mujoco_gl
from kinema.drivers.mujoco import names
from kinema.perception.depth import depth_to_cloud
from kinema.perception.intrinsics import CameraIntrinsics
from kinema.perception.point_cloud import PointCloud
from kinema.perception.ros_messages import camera_info_message, image_message, to_point_cloud2
from kinema.transforms import pose_matrix, quaternion_from_wxyz
from kinema.transport import Node, Session
from kinema.transport.keys import EntityKind

log = logging.getLogger("kinema.drivers.mujoco.cameras")

# libegl1 brings Mesa's EGL, libgl1 the GL library PyOpenGL loads, libgl1-mesa-dri the software
# rasteriser (llvmpipe) used where there is no GPU.
GL_HELP = (
    "MuJoCo needs OpenGL to render cameras. Headless: "
    "sudo apt-get install -y libegl1 libgl1 libgl1-mesa-dri "
    "(and MUJOCO_GL=egl, Kinema's default without a display), or sudo apt-get install -y libosmesa6 "
    "and MUJOCO_GL=osmesa (slower)"
)
# How often the camera thread looks for new subscribers, s of wall time.
POLL_PERIOD = 0.02
# Depths within this fraction of the far clipping plane are "nothing seen".
FAR_FRACTION = 0.99

# A MuJoCo camera looks along its -z with y up; the optical frame looks along z with y down.
_OPTICAL_IN_MUJOCO_CAMERA = np.diag([1.0, -1.0, -1.0])


@dataclass(frozen=True)
class CameraSpec:
    """One camera of the model.

    Attributes:
        name: the MuJoCo camera's name (and its topics' namespace).
        camera_id: its index in the model.
        frame_id: the body it is mounted in; images and clouds are in this frame.
        intrinsics: the pinhole the renderer uses.
        body_T_optical: 4x4 pose of the optical frame (z forward, y down) in ``frame_id``.
    """

    name: str
    camera_id: int
    frame_id: str
    intrinsics: CameraIntrinsics
    body_T_optical: np.ndarray


def camera_specs(model: Any) -> list[CameraSpec]:
    """The named cameras of ``model``, at their ``resolution`` (else the offscreen buffer's size)."""

    specs = []
    for camera_id in range(model.ncam):
        camera = model.camera(camera_id)
        if not camera.name:
            continue
        width, height = (int(v) for v in model.cam_resolution[camera_id])
        if width <= 1 or height <= 1:
            width, height = int(model.vis.global_.offwidth), int(model.vis.global_.offheight)
        transform = pose_matrix(model.cam_pos[camera_id], quaternion_from_wxyz(model.cam_quat[camera_id]))
        transform[:3, :3] = transform[:3, :3] @ _OPTICAL_IN_MUJOCO_CAMERA
        specs.append(
            CameraSpec(
                camera.name,
                camera_id,
                model.body(int(model.cam_bodyid[camera_id])).name,
                CameraIntrinsics.from_fovy(width, height, float(model.cam_fovy[camera_id])),
                transform,
            )
        )
    return specs


@dataclass(frozen=True)
class SimState:
    """What a render needs from the physics thread: sim time and the positions that place bodies."""

    time: float
    qpos: np.ndarray
    mocap_pos: np.ndarray
    mocap_quat: np.ndarray

    @classmethod
    def of(cls, data: Any) -> SimState:
        """A copy of ``data``'s state (call on the thread that owns ``data``)."""
        return cls(float(data.time), data.qpos.copy(), data.mocap_pos.copy(), data.mocap_quat.copy())


@dataclass(frozen=True)
class CameraFrame:
    """One rendered view: colour (HxWx3 uint8) and/or depth (HxW float32 m, NaN = nothing) at ``time``."""

    camera: CameraSpec
    time: float
    color: np.ndarray | None
    depth: np.ndarray | None

    def cloud(self) -> PointCloud:
        """The organised cloud of this depth (coloured if colour was rendered), in the body frame."""
        if self.depth is None:
            raise ValueError("this frame has no depth image")
        cloud = depth_to_cloud(
            self.depth, self.camera.intrinsics, self.color, frame_id=self.camera.frame_id, stamp=self.time
        )
        if np.allclose(self.camera.body_T_optical, np.eye(4)):
            return cloud
        return cloud.transformed(self.camera.body_T_optical)


class CameraRenderer:
    """Renders a model's cameras at a given state with an OpenGL context of its own.

    Use it from one thread (the context is made current on each render). Creating it fails with
    ``RuntimeError``/``ImportError`` etc. when no OpenGL context can be made; see :data:`GL_HELP`.
    """

    def __init__(self, model: Any) -> None:
        backend = os.environ.get("MUJOCO_GL", "").lower()
        if backend in ("disable", "disabled", "off", "false", "0"):
            raise RuntimeError(
                f"MuJoCo's rendering is off (MUJOCO_GL={backend}; Kinema sets this when there is no display "
                "and libEGL.so.1 or libOpenGL.so.0 cannot be loaded)"
            )
        import mujoco

        self.model = model
        self.data = mujoco.MjData(model)
        self._renderers: dict[tuple[int, int], Any] = {}
        self._option = mujoco.MjvOption()
        self._option.sitegroup[:] = 0  # sites are markers for people, not things a camera sees
        self._far = float(model.vis.map.zfar * model.stat.extent)
        # Fail here, not at the first frame, when there is no OpenGL.
        self._renderer(
            CameraIntrinsics.from_fovy(
                int(model.vis.global_.offwidth), int(model.vis.global_.offheight), 45.0
            )
        )

    def _renderer(self, intrinsics: CameraIntrinsics) -> Any:
        import mujoco

        size = (intrinsics.width, intrinsics.height)
        renderer = self._renderers.get(size)
        if renderer is None:
            renderer = mujoco.Renderer(self.model, intrinsics.height, intrinsics.width)
            # Shadows and reflections are extra render passes that cost about 40 % of a colour frame
            # in software OpenGL; a depth camera's picture does not need them.
            renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
            renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
            self._renderers[size] = renderer
        return renderer

    def set_state(self, state: SimState) -> None:
        """Pose the renderer's copy of the scene at ``state``."""
        import mujoco

        data = self.data
        data.time = state.time
        data.qpos[:] = state.qpos
        data.mocap_pos[:] = state.mocap_pos
        data.mocap_quat[:] = state.mocap_quat
        mujoco.mj_kinematics(self.model, data)
        mujoco.mj_camlight(self.model, data)

    def render(self, camera: CameraSpec, *, color: bool, depth: bool) -> CameraFrame:
        """Render ``camera`` at the last :meth:`set_state`."""
        renderer = self._renderer(camera.intrinsics)
        renderer.update_scene(self.data, camera=camera.camera_id, scene_option=self._option)
        rgb = renderer.render() if color else None
        metres = None
        if depth:
            renderer.enable_depth_rendering()
            try:
                metres = renderer.render()
            finally:
                renderer.disable_depth_rendering()
            metres[metres >= FAR_FRACTION * self._far] = np.nan
        return CameraFrame(camera, float(self.data.time), rgb, metres)

    def close(self) -> None:
        """Release the OpenGL contexts."""
        for renderer in self._renderers.values():
            renderer.close()
        self._renderers.clear()


class _ServedCamera:
    def __init__(self, spec: CameraSpec, node: Node) -> None:
        self.spec = spec
        self.node = node
        self.publishers = {
            stream: node.create_publisher(type_name, names.camera_topic(spec.name, stream))
            for stream, type_name in names.CAMERA_STREAMS.items()
        }
        self.next_due = 0.0

    def wanted(self, subscribed: set[str]) -> set[str]:
        return {stream for stream, pub in self.publishers.items() if pub.name in subscribed}


class CameraServer:
    """Serves every camera of a model on the transport while its topics have subscribers.

    Args:
        session: the transport session.
        model: the ``mujoco.MjModel``.
        snapshot: returns the current :class:`SimState` (from the physics thread), or None when the
            simulation is not running.
        rate: most frames per wall second per camera.
    """

    def __init__(
        self, session: Session, model: Any, snapshot: Callable[[], SimState | None], rate: float
    ) -> None:
        self.session = session
        self.model = model
        self.specs = camera_specs(model)
        self.rate = rate
        self._snapshot = snapshot
        self._types = session.registry.typestore.types
        self._cameras: list[_ServedCamera] = []
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.unavailable: str | None = None
        self.frames_rendered = 0
        self.ready = threading.Event()

    def start(self) -> None:
        """Declare the topics and start the camera thread (which makes the OpenGL context)."""
        for spec in self.specs:
            self._cameras.append(_ServedCamera(spec, Node(self.session, spec.name)))
        self._thread = threading.Thread(target=self._run, name="kinema-mujoco-cameras", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop rendering and withdraw the topics."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(10.0)
        self._close_nodes()

    def _close_nodes(self) -> None:
        for camera in self._cameras:
            camera.node.close()
        self._cameras = []

    def _run(self) -> None:
        try:
            renderer = CameraRenderer(self.model)
        except Exception as error:  # any failure to get an OpenGL context means: no cameras
            backend = os.environ.get("MUJOCO_GL", "glfw")
            self.unavailable = f"cannot render with MUJOCO_GL={backend}: {error}"
            if kinema.mujoco_gl.imported_too_early:
                self.unavailable += (
                    "; mujoco was imported before Kinema chose its OpenGL backend, so it kept GLFW: "
                    "import kinema.mujoco_gl before mujoco, or set MUJOCO_GL=egl in the environment"
                )
            log.warning("cameras unavailable (%s). %s", self.unavailable, GL_HELP)
            self._close_nodes()
            self.ready.set()
            return
        self.ready.set()
        log.info(
            "cameras ready: %s (rendered while subscribed, at most %g Hz)",
            ", ".join(s.name for s in self.specs),
            self.rate,
        )
        graph = self.session.graph_cache()
        try:
            while not self._stop.wait(POLL_PERIOD):
                now = time.perf_counter()
                due = [camera for camera in self._cameras if now >= camera.next_due]
                if not due:
                    continue
                # One look at the graph per poll for all cameras: this runs 50 times a second while the
                # physics thread wants the GIL.
                subscribed = {e.name for e in graph.snapshot().of_kind(EntityKind.SUBSCRIPTION)}
                for camera in due:
                    if self._stop.is_set():
                        break
                    wanted = camera.wanted(subscribed)
                    if wanted:
                        self._serve(camera, wanted, renderer)
        except Exception:
            log.exception("the camera thread stopped after an error")
        finally:
            renderer.close()

    def _serve(self, camera: _ServedCamera, wanted: set[str], renderer: CameraRenderer) -> None:
        now = time.perf_counter()
        state = self._snapshot()
        if state is None:
            return
        camera.next_due = now + (1.0 / self.rate if self.rate > 0 and math.isfinite(self.rate) else 0.0)
        spec, types = camera.spec, self._types
        if "camera_info" in wanted:
            camera.publishers["camera_info"].publish(
                camera_info_message(spec.intrinsics, spec.frame_id, state.time, types)
            )
        need_color = bool(wanted & {"color", "points"})
        need_depth = bool(wanted & {"depth", "points"})
        if not (need_color or need_depth):
            return
        renderer.set_state(state)
        frame = renderer.render(spec, color=need_color, depth=need_depth)
        self.frames_rendered += 1
        if "color" in wanted and frame.color is not None:
            camera.publishers["color"].publish(
                image_message(frame.color, "rgb8", spec.frame_id, state.time, types)
            )
        if "depth" in wanted and frame.depth is not None:
            camera.publishers["depth"].publish(
                image_message(frame.depth, "32FC1", spec.frame_id, state.time, types)
            )
        if "points" in wanted:
            camera.publishers["points"].publish(to_point_cloud2(frame.cloud(), types))
