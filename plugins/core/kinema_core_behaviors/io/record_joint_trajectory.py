"""RecordJointTrajectory: record the robot's motion between a start and a stop Trigger call.

While the behavior runs it serves two ``std_srvs/Trigger`` services. After ``start_recording_service``
is called, every joint state of ``planning_group_name`` that moved at least ``joint_space_step`` (rad or
m, largest joint change) from the last kept one becomes a trajectory point, timed from the joint state
stamps (sim time in simulation). ``stop_recording_service`` ends the recording: the trajectory goes to
``joint_trajectory_message`` and the behavior succeeds. Without a start call within ``timeout_sec`` it
fails; halting it stops recording and closes the services. The timeout passes only once it has passed in
sim time and in wall time (:class:`~kinema.behaviors.wait_deadline.WaitDeadline`): at maximum sim speed
the five seconds MoveIt Pro's "Record Square Trajectory" gives the other branch to plan and make its move
pass in sim time during the planning alone.
"""

from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

from kinema.behaviors import NodeStatus, PortInfo, StatefulBehavior, input_port
from kinema.behaviors.cell_ports import cell_input_port
from kinema.behaviors.wait_deadline import WaitDeadline

from ..messages.conversions import duration, seconds
from ..messages.ports import PortValueError, message_output, port_error, read_input


class _Recording:
    """The recorder shared by the services' and the subscription's threads."""

    def __init__(self, joints: list[str] | None, step: float) -> None:
        self.lock = threading.Lock()
        self.joints = joints
        self.step = step
        self.started = False
        self.stopped = False
        self.names: list[str] = []
        self.times: list[float] = []
        self.positions: list[np.ndarray] = []
        self.start_time: float | None = None

    def on_state(self, message: Any) -> None:
        import numpy as np

        with self.lock:
            if not self.started or self.stopped:
                return
            names = [str(n) for n in message.name]
            wanted = self.joints or names
            index = {name: i for i, name in enumerate(names)}
            if not all(name in index for name in wanted):
                return
            position = np.array([float(message.position[index[name]]) for name in wanted])
            stamp = seconds(message.header.stamp) or time.monotonic()
            if self.start_time is None:
                self.start_time = stamp
                self.names = list(wanted)
            elif float(np.max(np.abs(position - self.positions[-1]))) < self.step:
                return
            self.times.append(stamp - self.start_time)
            self.positions.append(position)

    def start(self, _request: Any) -> dict[str, Any]:
        with self.lock:
            if self.started:
                return {"success": False, "message": "already recording"}
            self.started = True
        return {"success": True, "message": "recording started"}

    def stop(self, _request: Any) -> dict[str, Any]:
        with self.lock:
            if not self.started:
                return {"success": False, "message": "not recording: call the start service first"}
            self.stopped = True
            count = len(self.positions)
        return {"success": True, "message": f"recording stopped with {count} points"}


class RecordJointTrajectory(StatefulBehavior):
    """Records a joint trajectory between calls of its start and stop Trigger services."""

    subcategory = "Motion - Execute"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("joint_state_topic", str, "/joint_states", "Joint states to record."),
            cell_input_port(
                "planning_group_name",
                str,
                "planning_group",
                "Group whose joints are recorded ('' = all joints).",
                empty_is_default=False,
            ),
            input_port(
                "start_recording_service", str, "/start_recording_joint_trajectory", "Trigger that starts."
            ),
            input_port(
                "stop_recording_service", str, "/stop_recording_joint_trajectory", "Trigger that stops."
            ),
            input_port(
                "timeout_sec",
                float,
                -1.0,
                "Seconds to wait for the start call, in sim time and in wall time (negative: forever).",
            ),
            input_port(
                "joint_space_step",
                float,
                0.01,
                "Smallest change of any joint (rad or m) between two recorded points (Kinema's default; "
                "MoveIt Pro's is not public).",
            ),
            message_output(
                "joint_trajectory_message",
                "trajectory_msgs/msg/JointTrajectory",
                "{joint_trajectory_msg}",
                "The recorded trajectory.",
            ),
        ]

    def __init__(self, name: str, config: Any = None) -> None:
        super().__init__(name, config)
        self._recording: _Recording | None = None
        self._entities: list[Any] = []
        self._deadline: WaitDeadline | None = None

    def _joints(self, group: str) -> list[str] | None:
        model = self.context.robot_model
        if not group or model is None:
            return None
        from kinema.errors import MotionError

        try:
            return list(model.group(group).joint_names)
        except MotionError as error:
            raise port_error(self, "planning_group_name", f"= {group!r}", error.message) from None

    def on_start(self) -> NodeStatus:
        try:
            step = float(read_input(self, "joint_space_step"))
            if step < 0:
                raise port_error(self, "joint_space_step", f"= {step} is negative", "give 0 or more")
            joints = self._joints(str(read_input(self, "planning_group_name")))
            node = self.context.require_node(self.registration_id)
            recording = _Recording(joints, step)
            self._entities = [
                node.create_subscription(
                    "sensor_msgs/msg/JointState",
                    str(read_input(self, "joint_state_topic")),
                    recording.on_state,
                ),
                node.create_service(
                    "std_srvs/srv/Trigger", str(read_input(self, "start_recording_service")), recording.start
                ),
                node.create_service(
                    "std_srvs/srv/Trigger", str(read_input(self, "stop_recording_service")), recording.stop
                ),
            ]
            timeout = float(read_input(self, "timeout_sec"))
        except PortValueError as error:
            self._close()
            self.logger.publish_failure(error.message)
            return NodeStatus.FAILURE
        self._recording = recording
        self._deadline = WaitDeadline(self.context.clock, timeout)
        return NodeStatus.RUNNING

    def on_running(self) -> NodeStatus:
        recording = self._recording
        assert recording is not None
        with recording.lock:
            started, stopped = recording.started, recording.stopped
        if not started:
            if self._deadline is not None and self._deadline.passed():
                self._close()
                self.logger.publish_failure("RecordJointTrajectory: the start service was not called in time")
                return NodeStatus.FAILURE
            return NodeStatus.RUNNING
        if not stopped:
            return NodeStatus.RUNNING
        self._close()
        if len(recording.positions) < 2:
            self.logger.publish_failure(
                f"RecordJointTrajectory: recorded {len(recording.positions)} point(s); the robot did not "
                "move more than joint_space_step between start and stop"
            )
            return NodeStatus.FAILURE
        self.set_output("joint_trajectory_message", _trajectory(recording))
        return NodeStatus.SUCCESS

    def on_halted(self) -> None:
        self._close()

    def _close(self) -> None:
        for entity in self._entities:
            try:
                entity.close()
            except Exception:  # closing twice (the node went first) is harmless
                pass
        self._entities = []


def _trajectory(recording: _Recording) -> Any:
    from kinema.transport import from_dict

    points = [
        {"positions": position.tolist(), "time_from_start": duration(t)}
        for t, position in zip(recording.times, recording.positions, strict=True)
    ]
    return from_dict(
        "trajectory_msgs/msg/JointTrajectory", {"joint_names": recording.names, "points": points}
    )
