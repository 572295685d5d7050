"""Velocity-force control: stream commands to the velocity-force controller, and watch the wrist's force.

MoveIt Pro's objectives pair the two in a ``Parallel`` (success_count 1): ``PublishVelocityForceCommand``
keeps the arm moving while ``ForceExceedsThreshold`` watches the force/torque sensor and succeeds on
contact, which halts the publisher; the controller then stops the arm once commands stop coming.
"""

from __future__ import annotations

import threading
import time
from typing import Any

from kinema.behaviors import NodeStatus, PortInfo, StatefulBehavior, input_port
from kinema.behaviors.cell_ports import cell_input_port

from ..messages.ports import (
    fails_on_bad_input,
    message_input,
    port_error,
    read_floats,
    read_input,
    read_message,
)

COMMAND_TYPE = "moveit_pro_controllers_msgs/msg/VelocityForceCommand"
WRENCH_TYPE = "geometry_msgs/msg/WrenchStamped"
AXES = ("x", "y", "z", "rx", "ry", "rz")


class PublishVelocityForceCommand(StatefulBehavior):
    """Streams a velocity/force command to the velocity-force controller until halted.

    Each axis of the controller's control frame (its end effector: ``grasp_link`` in lab_sim) is velocity
    controlled (it moves at ``twist``), force controlled (it moves at ``wrench_gain * (wrench - applied)``,
    coming to rest where the tool applies ``wrench``), or neither (it stays still). The command is sent at
    ``publish_rate`` (Hz of the runtime clock, sim time in simulation) with ``twist`` and ``wrench`` read
    again each time, so a tree may change them while it runs. It stays RUNNING until halted (by a
    ``Timeout`` or a ``Parallel`` whose other child finished); halting stops the stream, and the controller
    stops the arm when its command timeout (0.2 s) passes without a command. Activate the controller first
    (``SwitchController`` with ``velocity_force_controller``).
    """

    subcategory = "Motion - Controls"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "twist",
                "geometry_msgs/msg/Twist",
                description="Velocity of the control frame on the velocity-controlled axes (m/s, rad/s; "
                "e.g. from UnpackTwistStampedMessage).",
            ),
            message_input(
                "wrench",
                "geometry_msgs/msg/Wrench",
                description="Wrench the tool should apply on the force-controlled axes (N, N m; e.g. from "
                "UnpackWrenchStampedMessage). Zero makes the arm give way to any contact.",
            ),
            input_port(
                "velocity_controlled_axes",
                list[float],
                "0;0;0;0;0;0",
                "Six 0/1 flags x;y;z;rx;ry;rz: the axes that follow the twist.",
            ),
            input_port(
                "force_controlled_axes",
                list[float],
                "0;0;0;0;0;0",
                "Six 0/1 flags x;y;z;rx;ry;rz: the axes that follow the wrench (none may also be velocity "
                "controlled).",
            ),
            input_port(
                "wrench_gain",
                float,
                0.01,
                "Gain from force error to velocity on the force-controlled axes (m/s per N). The default "
                "is the value lab_sim's objectives use (MoveIt Pro's own default is not public).",
            ),
            input_port(
                "publish_rate",
                float,
                50.0,
                "Commands per second. The default is the rate lab_sim's objectives use (MoveIt Pro's own "
                "default is not public); keep it above 5 Hz, the controller's command timeout being 0.2 s.",
            ),
            input_port(
                "velocity_force_controller_command_topic",
                str,
                "/velocity_force_controller/command",
                "The controller's command topic.",
            ),
        ]

    def __init__(self, name: str, config: Any = None) -> None:
        super().__init__(name, config)
        self._publisher: Any = None
        self._period = 0.02
        self._next = 0.0
        self._timer: Any = None
        self._axes: tuple[list[bool], list[bool]] = ([False] * 6, [False] * 6)

    def _flags(self, port: str) -> list[bool]:
        values = read_floats(self, port, 6, "x;y;z;rx;ry;rz, each 0 or 1")
        if any(v not in (0.0, 1.0) for v in values):
            raise port_error(self, port, f"has {values}", "expected six flags x;y;z;rx;ry;rz, each 0 or 1")
        return [v == 1.0 for v in values]

    def _message(self) -> Any:
        from kinema.transport import from_dict

        twist = read_message(self, "twist", "geometry_msgs/msg/Twist")
        wrench = read_message(self, "wrench", "geometry_msgs/msg/Wrench")
        velocity_axes, force_axes = self._axes
        now = self.context.clock.now()
        return from_dict(
            COMMAND_TYPE,
            {
                "header": {"stamp": {"sec": int(now), "nanosec": int((now % 1.0) * 1e9)}},
                "twist": twist,
                "wrench": wrench,
                "velocity_controlled_axes": dict(zip(AXES, velocity_axes, strict=True)),
                "force_controlled_axes": dict(zip(AXES, force_axes, strict=True)),
                "wrench_gain": float(read_input(self, "wrench_gain")),
            },
        )

    @fails_on_bad_input
    def on_start(self) -> NodeStatus:
        velocity_axes = self._flags("velocity_controlled_axes")
        force_axes = self._flags("force_controlled_axes")
        both = [axis for axis, v, f in zip(AXES, velocity_axes, force_axes, strict=True) if v and f]
        if both:
            raise port_error(
                self,
                "force_controlled_axes",
                f"names {', '.join(both)}, which velocity_controlled_axes names too",
                "an axis follows either the twist or the wrench",
            )
        self._axes = (velocity_axes, force_axes)
        rate = float(read_input(self, "publish_rate"))
        if not rate > 0:
            raise port_error(self, "publish_rate", f"= {rate:g}", "give a rate above 0 Hz (e.g. 50)")
        topic = str(read_input(self, "velocity_force_controller_command_topic")).strip()
        if not topic:
            raise port_error(
                self,
                "velocity_force_controller_command_topic",
                "is empty",
                "give the controller's command topic, e.g. /velocity_force_controller/command",
            )
        node = self.context.require_node(self.registration_id)
        self._publisher = self.context.publisher(node, COMMAND_TYPE, topic)
        self._period = 1.0 / rate
        self._next = self.context.clock.now()
        return self._publish_when_due()

    @fails_on_bad_input
    def on_running(self) -> NodeStatus:
        return self._publish_when_due()

    def _publish_when_due(self) -> NodeStatus:
        clock = self.context.clock
        now = clock.now()
        if now >= self._next:
            self._publisher.publish(self._message())
            # The next slot on the rate's grid; slots missed while the tree was busy are not made up.
            self._next += self._period * max(1, int((now - self._next) / self._period) + 1)
            if self._timer is not None:
                self._timer.cancel()
            self._timer = clock.call_later(self._next - now, self.emit_wake_up_signal)
        return NodeStatus.RUNNING

    def on_halted(self) -> None:
        timer, self._timer = self._timer, None
        if timer is not None:
            timer.cancel()


class ForceExceedsThreshold(StatefulBehavior):
    """RUNNING until the wrist senses more than a force, then SUCCESS.

    Subscribes to the force/torque sensor's ``geometry_msgs/WrenchStamped`` topic and succeeds once the
    magnitude of the force (torque is not considered) has been above ``force_threshold`` in
    ``minimum_consecutive_wrench_values`` messages in a row; a message at or below it starts the count
    again. The reading is used as the sensor publishes it (its zero is the sensor's, not the moment the
    behavior started), and the magnitude is the same in ``wrench_frame_name`` and ``hand_frame_name``, so
    no transform is needed. It fails when no message arrives within 5 s (wall time) of starting, naming the
    topic: a silent sensor would otherwise guard nothing.
    """

    subcategory = "Motion - Controls"
    no_message_timeout = 5.0

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "wrench_topic_name",
                str,
                "/force_torque_sensor_broadcaster/wrench",
                "The sensor's WrenchStamped topic.",
            ),
            input_port("wrench_frame_name", str, "tool0", "Frame the sensor's wrench is expressed in."),
            cell_input_port(
                "hand_frame_name",
                str,
                "tool_frame",
                "The tool frame (kept for MoveIt Pro's objectives: the force magnitude is the same in it).",
            ),
            input_port("force_threshold", float, 30.0, "Force magnitude (N) that counts as exceeded."),
            input_port(
                "minimum_consecutive_wrench_values",
                int,
                5,
                "How many messages in a row must exceed the threshold.",
            ),
        ]

    def __init__(self, name: str, config: Any = None) -> None:
        super().__init__(name, config)
        self._lock = threading.Lock()
        self._subscription: Any = None
        self._watchdog: threading.Timer | None = None
        self._started = 0.0
        self._received = 0
        self._in_a_row = 0
        self._threshold = 0.0
        self._needed = 1
        self._exceeded = False

    @fails_on_bad_input
    def on_start(self) -> NodeStatus:
        threshold = float(read_input(self, "force_threshold"))
        if not threshold >= 0:
            raise port_error(self, "force_threshold", f"= {threshold:g}", "give a force in N, 0 or more")
        needed = int(read_input(self, "minimum_consecutive_wrench_values"))
        if needed < 1:
            raise port_error(self, "minimum_consecutive_wrench_values", f"= {needed}", "give 1 or more")
        topic = str(read_input(self, "wrench_topic_name")).strip()
        if not topic:
            raise port_error(
                self,
                "wrench_topic_name",
                "is empty",
                "give the sensor's topic, e.g. /force_torque_sensor_broadcaster/wrench",
            )
        self._threshold, self._needed = threshold, needed
        with self._lock:
            self._received = self._in_a_row = 0
            self._exceeded = False
        node = self.context.require_node(self.registration_id)
        self._subscription = node.create_subscription(WRENCH_TYPE, topic, self._on_wrench)
        self._started = time.monotonic()
        self._watchdog = threading.Timer(self.no_message_timeout, self.emit_wake_up_signal)
        self._watchdog.daemon = True
        self._watchdog.start()
        return NodeStatus.RUNNING

    def _on_wrench(self, message: Any) -> None:
        import numpy as np

        force = message.wrench.force
        magnitude = float(np.linalg.norm((force.x, force.y, force.z)))
        with self._lock:
            self._received += 1
            self._in_a_row = self._in_a_row + 1 if magnitude > self._threshold else 0
            if self._in_a_row >= self._needed and not self._exceeded:
                self._exceeded = True
            else:
                return
        self.emit_wake_up_signal()

    def on_running(self) -> NodeStatus:
        with self._lock:
            exceeded, received = self._exceeded, self._received
        if exceeded:
            self._close()
            self.logger.publish_info(
                f"ForceExceedsThreshold: the force exceeded {self._threshold:g} N ({self._needed} in a row)"
            )
            return NodeStatus.SUCCESS
        if received == 0 and time.monotonic() - self._started > self.no_message_timeout:
            topic = str(read_input(self, "wrench_topic_name"))
            self._close()
            self.logger.publish_failure(
                f"ForceExceedsThreshold: no wrench on {topic} within {self.no_message_timeout:g} s; is the "
                "force/torque sensor broadcaster running? (kinema topic list shows the topics)"
            )
            return NodeStatus.FAILURE
        return NodeStatus.RUNNING

    def on_halted(self) -> None:
        self._close()

    def _close(self) -> None:
        watchdog, self._watchdog = self._watchdog, None
        if watchdog is not None:
            watchdog.cancel()
        subscription, self._subscription = self._subscription, None
        if subscription is not None:
            try:
                subscription.close()
            except Exception:  # the node may have gone first; closing twice is harmless
                pass
