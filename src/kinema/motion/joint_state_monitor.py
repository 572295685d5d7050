"""The robot's current joint state, as the driver publishes it on ``/joint_states``.

One :class:`JointStateMonitor` serves every behavior of a cell (``BehaviorContext.joint_states``; the
subscription lives as long as the context's transport node), so planning behaviors read the start state
without waiting for the next message, and a camera frame can be placed where the robot was when it was
taken.
"""

from __future__ import annotations

import bisect
import struct
import threading
import time
from collections import deque
from collections.abc import Sequence
from typing import Any

import numpy as np

from kinema.drivers.mujoco.names import JOINT_STATES_TOPIC, JOINT_STATES_TYPE
from kinema.errors import ObjectiveError

__all__ = ["HISTORY", "OTHER_CLOCK", "JointStateMonitor"]

# Messages kept for lookups at a past stamp: 6 s of sim time at the driver's 100 Hz.
HISTORY = 600
# A stamp further than this from the robot's clock is another clock (a camera not synchronised with the
# robot, or a zero stamp): the latest state is used for it.
OTHER_CLOCK = 30.0


class JointStateMonitor:
    """Keeps the latest ``/joint_states`` message, and the last few seconds of them for lookups at a stamp.

    Args:
        node: the transport node to subscribe on.
        topic: the joint state topic.
    """

    def __init__(self, node: Any, topic: str = JOINT_STATES_TOPIC) -> None:
        self.topic = topic
        # Messages are kept as received (CDR) and decoded when a behavior reads one: a simulation at full
        # speed publishes thousands a second, and decoding each took the interpreter from the tick thread,
        # planning and the simulation for most of a motion. Only the header's stamp is read on arrival.
        self._registry = node.session.registry
        self._latest_raw: bytes | None = None
        self._decoded: tuple[bytes | None, Any] = (None, None)
        self._received_at = 0.0
        self._stamps: deque[float] = deque(maxlen=HISTORY)
        self._history: deque[bytes] = deque(maxlen=HISTORY)
        self._changed = threading.Condition()
        self._subscription = node.create_subscription(JOINT_STATES_TYPE, topic, self._on_message, raw=True)

    def _on_message(self, payload: bytes) -> None:
        stamp = _header_stamp(payload)
        if stamp is None:
            stamp = self._decode(payload).header.stamp
            stamp = stamp.sec + stamp.nanosec * 1e-9
        with self._changed:
            self._latest_raw = payload
            self._received_at = time.monotonic()
            if self._stamps and stamp < self._stamps[-1]:
                # The clock went back (a reset simulation): the old history is another timeline.
                self._stamps.clear()
                self._history.clear()
            self._stamps.append(stamp)
            self._history.append(payload)
            self._changed.notify_all()

    def _decode(self, payload: bytes) -> Any:
        """The message of ``payload`` (the last one decoded is kept: readers ask for the latest)."""
        decoded = self._decoded
        if decoded[0] is payload:
            return decoded[1]
        message = self._registry.deserialize(payload, JOINT_STATES_TYPE)
        self._decoded = (payload, message)
        return message

    @property
    def _latest(self) -> Any:
        payload = self._latest_raw
        return None if payload is None else self._decode(payload)

    @property
    def received(self) -> bool:
        """Whether a message has arrived yet."""
        return self._latest_raw is not None

    def latest(self, timeout: float = 2.0) -> Any:
        """The latest message; waits up to ``timeout`` s for the first one.

        Raises:
            ObjectiveError: nothing was received within ``timeout`` (no driver running).
        """
        with self._changed:
            if self._latest_raw is None and not self._changed.wait_for(
                lambda: self._latest_raw is not None, timeout
            ):
                raise ObjectiveError(
                    f"no joint state received on {self.topic} within {timeout:g} s; is the robot driver "
                    "running (`kinema run`)?"
                )
            return self._latest

    def fresh(self, timeout: float = 2.0) -> Any:
        """The next message received from now on (a state at least as new as this call)."""
        with self._changed:
            since = self._received_at
            if not self._changed.wait_for(lambda: self._received_at > since, timeout):
                raise ObjectiveError(
                    f"no joint state received on {self.topic} within {timeout:g} s; is the robot driver "
                    "running (`kinema run`)?"
                )
            return self._latest

    def positions(self, joint_names: Sequence[str], timeout: float = 2.0) -> np.ndarray:
        """Latest positions of ``joint_names``, in that order.

        Raises:
            ObjectiveError: no message yet, or a joint is missing from it.
        """
        return self._named(self.latest(timeout), joint_names)

    def current_positions(self, joint_names: Sequence[str], clock: Any, timeout: float = 2.0) -> np.ndarray:
        """Positions of ``joint_names`` now, by ``clock`` (the agent's: sim time in simulation), as MoveIt's
        current state monitor waits for a state at least as new as the request.

        The latest message received can be older than the robot: after a motion the execution's result
        may arrive before the last joint states do (a simulation far faster than real time publishes
        thousands a second). A plan started from such a state begins where the arm no longer is. This
        waits up to ``timeout`` for a state stamped at or after ``clock.now()``; a robot on another clock
        (stamps more than 30 s away) gets the latest state.

        Raises:
            ObjectiveError: no message yet, or a joint is missing from it.
        """
        self.latest(timeout)
        now = float(clock.now()) if clock is not None else 0.0
        with self._changed:
            newest = self._stamps[-1] if self._stamps else 0.0
            if now > 0 and abs(now - newest) <= OTHER_CLOCK:
                self._changed.wait_for(lambda: bool(self._stamps) and self._stamps[-1] >= now, timeout)
            message = self._latest
        return self._named(message, joint_names)

    def positions_at(self, joint_names: Sequence[str], stamp: float, timeout: float = 2.0) -> np.ndarray:
        """Positions of ``joint_names`` at ``stamp`` (s, the robot's clock), as TF looks up a transform at a
        message's stamp: a camera frame is placed where the camera was when it was taken, not where it
        is when the frame is read (the arm may have moved on, or the newest joint state may still be on
        its way on a loaded machine).

        Waits up to ``timeout`` for a state stamped at or after ``stamp``, then interpolates between the
        two states around it. A stamp of 0, on another clock (more than 30 s from the robot's) or older
        than the history gets the latest or the oldest kept state.

        Raises:
            ObjectiveError: no message yet, or a joint is missing from it.
        """
        self.latest(timeout)
        if stamp <= 0:
            return self.positions(joint_names, timeout)
        with self._changed:
            newest = self._stamps[-1]
            if abs(stamp - newest) > OTHER_CLOCK:
                return self._named(self._latest, joint_names)
            self._changed.wait_for(lambda: self._stamps[-1] >= stamp, timeout)
            stamps, history = list(self._stamps), list(self._history)
        after = bisect.bisect_left(stamps, stamp)
        if after >= len(stamps):
            return self._named(self._decode(history[-1]), joint_names)
        if after == 0 or stamps[after] == stamp:
            return self._named(self._decode(history[after]), joint_names)
        t0, t1 = stamps[after - 1], stamps[after]
        q0 = self._named(self._decode(history[after - 1]), joint_names)
        q1 = self._named(self._decode(history[after]), joint_names)
        return q0 + (q1 - q0) * ((stamp - t0) / (t1 - t0))

    def _named(self, message: Any, joint_names: Sequence[str]) -> np.ndarray:
        index = {str(name): i for i, name in enumerate(message.name)}
        missing = [name for name in joint_names if name not in index]
        if missing:
            raise ObjectiveError(
                f"{self.topic} does not report joint(s) {', '.join(missing)} "
                f"(it reports {', '.join(index) or 'none'})"
            )
        return np.array([float(message.position[index[name]]) for name in joint_names])

    def close(self) -> None:
        """Stop listening."""
        self._subscription.close()


def _header_stamp(payload: bytes) -> float | None:
    """The header stamp (s) of a CDR ``sensor_msgs/JointState``: its first field, right after the 4-byte
    encapsulation header (int32 sec, uint32 nanosec); None for an encoding this does not read."""
    if len(payload) < 12 or payload[0] != 0 or payload[1] not in (0, 1):
        return None
    sec, nanosec = struct.unpack_from("<iI" if payload[1] == 1 else ">iI", payload, 4)
    return sec + nanosec * 1e-9
