"""Asking the user for values: a pose (RetrievePoseParameter), joint values (RetrieveRobotStateParameter),
points on an image (GetPointsFromUser), and a teleoperation session (DoTeleoperateAction), in the TUI when
one is attached.

A UI that can ask the user serves ``/kinema/user_input`` (``kinema_msgs/srv/RequestUserInput``); the TUI
does while it is open, as it serves the approvals (:mod:`.approval`). MoveIt Pro's web UI answers these
behaviors through its parameter manager and its teleoperation action; Kinema's UIs answer the one service.

**Headless rule**, as for approvals: without a UI nothing is invented, the behavior fails with a message
saying no user is attached; with ``KINEMA_AUTO_APPROVE=1`` (``kinema run --auto-approve``) each is
answered at once the way a user who changes nothing would, with a warning toast saying so:

- RetrievePoseParameter: the tool frame (``robot.tool_frame``) where it is now, in the world frame;
- RetrieveRobotStateParameter: the planning group's joints where they are now;
- GetPointsFromUser: the centre of the latest image of ``view_name``, once per point;
- DoTeleoperateAction: the session ends at once, the robot where it is.
"""

from __future__ import annotations

import threading
import time
from typing import Any

from kinema.behaviors import (
    AsyncBehavior,
    FormerSpelling,
    NodeStatus,
    PortInfo,
    StatefulBehavior,
    input_port,
    output_port,
)
from kinema.behaviors.cell_ports import cell_input_port
from kinema.config.cell import JOINT_TRAJECTORY_CONTROLLER
from kinema.errors import KinemaError, TransportError
from kinema.ui_topics import (
    TELEOPERATION_MODE_TOPIC,
    TELEOPERATION_MODE_TYPE,
    USER_INPUT_SERVICE,
    USER_INPUT_TYPE,
)

from ..messages.conversions import joint_state_message, pose_stamped_message
from ..messages.ports import PortValueError, fails_on_bad_input, message_output, port_error, read_input
from ..motion.joint_states import joint_state_monitor
from .approval import AUTO_APPROVE_ENV, DISCOVERY_SECONDS, auto_approve

# How long the user may take (an hour at most; halting the node stops waiting for them).
ANSWER_SECONDS = 3600.0
# How long RetrieveRobotStateParameter waits for the robot's joint state to start the form from.
JOINT_STATE_SECONDS = 5.0
# MoveIt Pro 10's teleoperation slots a retrieval reads (its ``command_type``).
COMMAND_TYPES = ("waypoint", "joint_slider", "interactive_marker")
# How long an automatic answer waits for an image to learn its size.
IMAGE_SECONDS = 10.0
IMAGE_TYPE = "sensor_msgs/msg/Image"
POINT_TYPE = "geometry_msgs/msg/PointStamped"


def user_input_client(behavior: Any) -> Any | None:
    """The user-input service client of ``behavior``'s context, or None without a transport node."""
    node = behavior.context.node
    if node is None:
        return None
    return behavior.context.service_client(node, USER_INPUT_TYPE, USER_INPUT_SERVICE)


def no_user_message(behavior: Any, what: str) -> str:
    """The headless rule's failure: nobody is attached to give ``what``."""
    return (
        f"{behavior.registration_id}: no user interface is attached to {what}; open `kinema ui`, or run "
        f"headless with `kinema run --auto-approve` ({AUTO_APPROVE_ENV}=1) to answer it automatically"
    )


def _request(behavior: Any, kind: str, prompt: str, **fields: Any) -> dict[str, Any]:
    return {
        "behavior": behavior.registration_id,
        "node_path": behavior.full_path,
        "prompt": prompt,
        "kind": kind,
        **fields,
    }


async def ask_user(behavior: Any, request: dict[str, Any], timeout: float = ANSWER_SECONDS) -> Any | None:
    """The UI's response to ``request``, or None when no UI serves ``/kinema/user_input``.

    Raises:
        TransportError: the UI did not answer within ``timeout`` seconds.
    """
    import asyncio

    client = user_input_client(behavior)
    if client is None or not await asyncio.to_thread(client.wait_for_service, DISCOVERY_SECONDS):
        return None
    return await asyncio.wrap_future(client.call_async(request, timeout))


#: :func:`_ask_for`'s answer when no user is attached and ``--auto-approve`` answers for them (the caller
#: decides what a user changing nothing would have answered).
NO_USER_AUTO = object()


async def _ask_for(
    behavior: Any, request: dict[str, Any], timeout: float, *, what: str, giving: str, refused: str
) -> Any:
    """The user's accepted answer to ``request``; :data:`NO_USER_AUTO` when no user is attached and
    auto-approval is on; None when there is no answer (the failure is reported, naming the behavior, with
    ``what`` was asked, what the user was to be ``giving``, and what the user did when ``refused``)."""
    name = type(behavior).__name__
    try:
        response = await ask_user(behavior, request, timeout)
    except TransportError as error:
        behavior.logger.publish_failure(f"{name}: no {what} from the user: {error.message}")
        return None
    if response is None:
        if auto_approve():
            return NO_USER_AUTO
        behavior.logger.publish_failure(no_user_message(behavior, giving))
        return None
    if not response.accepted:
        said = f": {response.message}" if str(response.message) else ""
        behavior.logger.publish_failure(f"{name}: the user {refused}{said}")
        return None
    return response


async def _ask_from_here(
    behavior: Any,
    kind: str,
    prompt: str,
    start: Any,
    timeout_sec: float,
    *,
    what: str,
    giving: str,
    refused: str,
    start_is: str,
) -> Any:
    """The user's answer to a ``kind`` question whose form is prefilled with ``start`` (the request's
    ``initial_<kind>``), waited for ``timeout_sec`` (negative: up to :data:`ANSWER_SECONDS`); None when
    there is none (reported as :func:`_ask_for` does). With no user attached and auto-approval on, ``start``
    is the answer: it is written to the output port ``kind`` with a warning that it is ``start_is``, and
    :data:`NO_USER_AUTO` is returned."""
    response = await _ask_for(
        behavior,
        _request(behavior, kind, prompt, **{f"initial_{kind}": start}),
        ANSWER_SECONDS if timeout_sec < 0 else timeout_sec,
        what=what,
        giving=giving,
        refused=refused,
    )
    if response is NO_USER_AUTO:
        behavior.logger.publish_warn(
            f"{prompt} — answered automatically with {start_is} ({AUTO_APPROVE_ENV}=1)"
        )
        behavior.set_output(kind, start)
    return response


def _tool_pose(behavior: Any) -> Any:
    """The config's tool frame where it is now, as a PoseStamped in the world frame."""
    from ..poses.frame_tree import current_frame_tree

    cell = behavior.context.cell
    frame = cell.tool_frame if cell is not None and cell.tool_frame else None
    if frame is None:
        raise KinemaError("the config names no tool frame (robot.tool_frame)")
    return pose_stamped_message("world", current_frame_tree(behavior).world_T(frame))


class RetrievePoseParameter(AsyncBehavior):
    """Asks the user for a pose and writes it to ``pose`` (MoveIt Pro: the pose its UI's interactive marker
    stores). The TUI asks with a form prefilled with the tool frame's current pose; see the module for the
    headless rule. Fails when the user cancels or no answer comes within ``timeout_sec``.
    """

    subcategory = "User Input"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "timeout_sec",
                float,
                -1.0,
                "Seconds to wait for the user's pose (negative: as long as it takes, up to an hour).",
            ),
            message_output("pose", "geometry_msgs/msg/PoseStamped", "{pose}", "The pose the user gave."),
        ]

    @fails_on_bad_input
    async def do_work(self) -> bool:
        import asyncio

        timeout = float(read_input(self, "timeout_sec"))
        try:
            start = await asyncio.to_thread(_tool_pose, self)
        except KinemaError as error:
            self.logger.publish_failure(f"RetrievePoseParameter: {error}")
            return False
        response = await _ask_from_here(
            self,
            "pose",
            "Give the target pose",
            start,
            timeout,
            what="pose",
            giving="give a pose",
            refused="gave no pose",
            start_is="the tool frame where it is",
        )
        if response is None:
            return False
        if response is not NO_USER_AUTO:
            self.set_output("pose", response.pose)
        return True


class RetrieveRobotStateParameter(AsyncBehavior):
    """Asks the user for joint values and writes them to ``joint_state`` (MoveIt Pro: the robot state its
    UI's joint sliders or waypoint buttons store; formerly RetrieveJointStateParameter). The question covers
    the config's planning group (``moveit_params.joint_group_name``; every joint of ``/joint_states``
    without one), and the TUI asks with a form prefilled with where those joints are now; see the module
    for the headless rule. Fails when the user cancels, answers joints that were not asked, or no answer
    comes within ``timeout_sec``.
    """

    subcategory = "User Input"
    former_spellings = (FormerSpelling("RetrieveJointStateParameter"),)

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "timeout_sec",
                float,
                -1.0,
                "Seconds to wait for the user's joint values (negative: as long as it takes, up to an hour).",
            ),
            input_port(
                "command_type",
                str,
                "",
                "MoveIt Pro 10's teleoperation slot the target is read from (waypoint, joint_slider or "
                "interactive_marker). Kinema's UIs answer the question directly, so the slot only names the "
                "question; '' (files older than MoveIt Pro 10) asks the same way.",
            ),
            message_output(
                "joint_state",
                "sensor_msgs/msg/JointState",
                "{joint_state}",
                "The joint values the user gave (what Move to Joint State and Interpolate to Joint State "
                "take as target_joint_state).",
            ),
        ]

    @fails_on_bad_input
    async def do_work(self) -> bool:
        import asyncio

        timeout = float(read_input(self, "timeout_sec"))
        slot = str(self.get_input_or("command_type", "") or "").strip()
        if slot and slot not in COMMAND_TYPES:
            raise port_error(
                self, "command_type", f"= {slot!r} is no teleoperation slot", _one_of(COMMAND_TYPES)
            )
        try:
            start = await asyncio.to_thread(self._current_joints)
        except KinemaError as error:
            self.logger.publish_failure(f"RetrieveRobotStateParameter: {error}")
            return False
        prompt = "Give the target joint values" + (f" ({slot.replace('_', ' ')})" if slot else "")
        response = await _ask_from_here(
            self,
            "joint_state",
            prompt,
            start,
            timeout,
            what="joint values",
            giving="give joint values",
            refused="gave no joint values",
            start_is="the joints where they are",
        )
        if response is None:
            return False
        if response is NO_USER_AUTO:
            return True
        answer = response.joint_state
        asked = [str(name) for name in start.name]
        names, positions = [str(name) for name in answer.name], [float(p) for p in answer.position]
        unknown = [name for name in names if name not in asked]
        if not names or unknown or len(positions) != len(names):
            problem = (
                f"joints that were not asked: {', '.join(unknown)}"
                if unknown
                else f"{len(names)} names and {len(positions)} positions"
            )
            self.logger.publish_failure(
                f"RetrieveRobotStateParameter: the UI answered {problem}; the question was about "
                f"{', '.join(asked)}"
            )
            return False
        self.set_output("joint_state", joint_state_message(names, positions))
        return True

    def _current_joints(self) -> Any:
        """The config's planning group's joints (or all of ``/joint_states``) where they are now."""
        message = joint_state_monitor(self.context, self.registration_id).fresh(JOINT_STATE_SECONDS)
        current = dict(
            zip((str(n) for n in message.name), (float(p) for p in message.position), strict=False)
        )
        cell, model = self.context.cell, self.context.robot_model
        group = cell.planning_group if cell is not None else None
        if not group or model is None:
            return joint_state_message(list(current), list(current.values()))
        if group not in model.groups:
            raise KinemaError(
                f"the config's planning group {group!r} (moveit_params.joint_group_name) is not in the "
                f"robot's SRDF; groups: {', '.join(model.groups)}"
            )
        joints = list(model.group(group).joint_names)
        missing = [name for name in joints if name not in current]
        if missing:
            raise KinemaError(f"/joint_states lacks {', '.join(missing)} of planning group {group!r}")
        return joint_state_message(joints, [current[name] for name in joints])


def _one_of(values: tuple[str, ...]) -> str:
    return "give one of " + ", ".join(values) + ", or leave it empty"


class GetPointsFromUser(AsyncBehavior):
    """Asks the user to click one point per prompt on the image of ``view_name`` and writes the pixels to
    ``pixel_coords`` (a vector of ``geometry_msgs/PointStamped``: x the column, y the row; each header's
    frame_id is the point's name). MoveIt Pro's web UI shows its camera views; the TUI shows the image and
    takes clicks or typed pixels. See the module for the headless rule. Fails when the user cancels.
    """

    subcategory = "User Input"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            cell_input_port("view_name", str, "camera_color_topic", "The image topic the user clicks on."),
            input_port("point_prompts", None, "", "What to click, one prompt per point (a;b;c)."),
            input_port("point_names", None, "", "A name per point (a;b;c), each point's frame_id."),
            output_port(
                "pixel_coords",
                None,
                "{pixel_coords}",
                "The clicked pixels (std::vector<geometry_msgs/PointStamped>).",
            ),
        ]

    def _strings(self, port: str) -> list[str]:
        value = self.get_input_or(port, "")
        if isinstance(value, str):
            items = value.split(";")
        elif isinstance(value, list | tuple):
            items = [str(item) for item in value]
        else:
            raise port_error(self, port, f"= {value!r} is not a list of strings", "give a;b;c")
        return [item.strip() for item in items if item.strip()]

    @fails_on_bad_input
    async def do_work(self) -> bool:
        import asyncio

        view = str(read_input(self, "view_name")).strip()
        prompts = self._strings("point_prompts")
        names = self._strings("point_names")
        if not prompts:
            raise port_error(self, "point_prompts", "is empty", "give one prompt per point: a;b;c")
        names += [f"point_{i + 1}" for i in range(len(names), len(prompts))]
        prompt = prompts[0] if len(prompts) == 1 else f"Click {len(prompts)} points on {view}"
        request = _request(
            self, "points", prompt, image_topic=view, point_prompts=prompts, point_names=names[: len(prompts)]
        )
        response = await _ask_for(
            self,
            request,
            ANSWER_SECONDS,
            what="points",
            giving=f"click points on {view}",
            refused="clicked no points",
        )
        if response is None:
            return False
        if response is NO_USER_AUTO:
            try:
                width, height = await asyncio.to_thread(self._image_size, view)
            except PortValueError as error:
                self.logger.publish_failure(error.message)
                return False
            pixels = [(width / 2.0, height / 2.0)] * len(prompts)
            self.logger.publish_warn(
                f"{prompt} — answered automatically with the image's centre ({AUTO_APPROVE_ENV}=1)"
            )
        else:
            pixels = [(float(p.x), float(p.y)) for p in response.points]
            if len(pixels) != len(prompts):
                self.logger.publish_failure(
                    f"GetPointsFromUser: asked for {len(prompts)} points, the UI answered {len(pixels)}"
                )
                return False
        self.set_output("pixel_coords", _points(names, pixels))
        return True

    def _image_size(self, topic: str) -> tuple[int, int]:
        node = self.context.require_node(self.registration_id)
        box: list[Any] = []
        arrived = threading.Event()

        def on_image(message: Any) -> None:
            box.append(message)
            arrived.set()

        subscription = node.create_subscription(IMAGE_TYPE, topic, on_image)
        try:
            if not arrived.wait(IMAGE_SECONDS):
                raise port_error(
                    self, "view_name", f"= {topic!r}: no image within {IMAGE_SECONDS:g} s to answer on"
                )
        finally:
            subscription.close()
        return int(box[0].width), int(box[0].height)


def _points(names: list[str], pixels: list[tuple[float, float]]) -> list[Any]:
    from kinema.transport import from_dict

    return [
        from_dict(POINT_TYPE, {"header": {"frame_id": name}, "point": {"x": x, "y": y, "z": 0.0}})
        for name, (x, y) in zip(names, pixels, strict=False)
    ]


class DoTeleoperateAction(StatefulBehavior):
    """Opens a teleoperation session in the UI and runs until the user ends it (SUCCESS) or cancels it
    (FAILURE), as MoveIt Pro's web UI does through its DoTeleoperate action.

    While it runs, ``current_teleop_mode`` follows the mode the user picks (moveit_studio_sdk_msgs/
    TeleoperationMode: 3 waypoint, 4 interactive marker, 6 open gripper, 7 close gripper, ...), so a
    tree beside it ("Request Teleoperation") can act on it. ``planning_groups``, ``controllers`` and
    ``tip_links`` are written at the start from the config (its planning group, the trajectory controller
    active at startup and the tool frame), as MoveIt Pro's UI reports them. See the module for the
    headless rule.
    """

    subcategory = "User Input"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "enable_user_interaction",
                bool,
                False,
                "Show user_interaction_prompt with Done and Cancel (Kinema's TUI always shows them).",
            ),
            input_port("user_interaction_prompt", str, "", "What the user is asked to do."),
            input_port("initial_teleop_mode", int, 3, "The mode the session starts in (TeleoperationMode)."),
            output_port("current_teleop_mode", int, "{current_teleop_mode}", "The mode the user picked."),
            output_port("planning_groups", None, "{planning_groups}", "The planning groups teleoperated."),
            output_port("controllers", None, "{controllers}", "The controllers that move them."),
            output_port("skip_collision_checks", bool, "{skip_collision_checks}", "Always false in Kinema."),
            output_port("tip_links", None, "{tip_links}", "The tool frame of each planning group."),
        ]

    def __init__(self, name: str, config: Any = None) -> None:
        super().__init__(name, config)
        self._client: Any = None
        self._subscription: Any = None
        self._answer: Any = None
        self._modes: list[int] = []
        self._lock = threading.Lock()
        self._deadline = 0.0
        self._prompt = ""

    def on_start(self) -> NodeStatus:
        try:
            mode = int(read_input(self, "initial_teleop_mode"))
            prompt = str(self.get_input_or("user_interaction_prompt", "") or "").strip()
        except PortValueError as error:
            self.logger.publish_failure(error.message)
            return NodeStatus.FAILURE
        self._prompt = prompt or "Teleoperate the robot; press Done when it is where you want it"
        self.set_output("current_teleop_mode", mode)
        self._write_session_outputs()
        self._answer = None
        self._modes = []
        self._client = user_input_client(self)
        if self._client is None:
            return self._without_user()
        self._deadline = time.monotonic() + DISCOVERY_SECONDS
        return self.on_running()

    def _write_session_outputs(self) -> None:
        cell = self.context.cell
        group = cell.planning_group if cell is not None and cell.planning_group else ""
        tool = cell.tool_frame if cell is not None and cell.tool_frame else ""
        self.set_output("planning_groups", [group] if group else [])
        trajectory = [
            spec.name
            for spec in (cell.controllers.values() if cell is not None else ())
            if spec.active and spec.type == JOINT_TRAJECTORY_CONTROLLER
        ]
        self.set_output("controllers", trajectory[:1])
        self.set_output("skip_collision_checks", False)
        self.set_output("tip_links", [tool] if tool else [])

    def _without_user(self) -> NodeStatus:
        if auto_approve():
            self.logger.publish_warn(
                f"{self._prompt} — ended automatically with the robot where it is ({AUTO_APPROVE_ENV}=1)"
            )
            return NodeStatus.SUCCESS
        self.logger.publish_failure(no_user_message(self, "teleoperate the robot"))
        return NodeStatus.FAILURE

    def _open_session(self) -> None:
        node = self.context.require_node(self.registration_id)
        self._subscription = node.create_subscription(
            TELEOPERATION_MODE_TYPE, TELEOPERATION_MODE_TOPIC, self._on_mode
        )
        request = _request(
            self,
            "teleoperate",
            self._prompt,
            initial_teleop_mode=int(self.get_input_or("initial_teleop_mode", 3)),
        )
        self._answer = self._client.call_async(request, ANSWER_SECONDS)

    def _on_mode(self, message: Any) -> None:
        with self._lock:
            self._modes.append(int(message.data))

    def on_running(self) -> NodeStatus:
        if self._answer is None:
            if self._client.service_is_ready():
                self._open_session()
            elif time.monotonic() >= self._deadline:
                return self._without_user()
            return NodeStatus.RUNNING
        with self._lock:
            modes, self._modes = self._modes, []
        if modes:
            self.set_output("current_teleop_mode", modes[-1])
        if not self._answer.done():
            return NodeStatus.RUNNING
        self._close()
        try:
            response = self._answer.result()
        except TransportError as error:
            self.logger.publish_failure(f"DoTeleoperateAction: the session ended without an answer: {error}")
            return NodeStatus.FAILURE
        if not response.accepted:
            said = f": {response.message}" if str(response.message) else ""
            self.logger.publish_failure(f"DoTeleoperateAction: the user cancelled teleoperation{said}")
            return NodeStatus.FAILURE
        return NodeStatus.SUCCESS

    def on_halted(self) -> None:
        if self._answer is not None:
            self._answer.cancel()
        self._close()

    def _close(self) -> None:
        if self._subscription is not None:
            self._subscription.close()
            self._subscription = None
