"""What every driver is: something that owns hardware or a simulator and serves it on the transport.

A driver is started and stopped by whoever runs it (``kinema run`` in a process of its own, a test
in-process) and tells what it serves, so a supervisor can wait until the robot is reachable and a user
can see which topics, services and actions belong to it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, Protocol, runtime_checkable

InterfaceKind = Literal["topic", "service", "action"]


@dataclass(frozen=True)
class ServedInterface:
    """One topic, service or action a driver offers.

    Attributes:
        kind: ``topic`` (published), ``service`` or ``action`` (served).
        name: fully qualified name, e.g. ``/joint_trajectory_controller/follow_joint_trajectory``.
        type_name: ROS type, e.g. ``control_msgs/action/FollowJointTrajectory``.
        description: one line for people.
    """

    kind: InterfaceKind
    name: str
    type_name: str
    description: str = ""


@runtime_checkable
class Driver(Protocol):
    """The contract between a driver and what runs it.

    ``start`` returns once everything in :meth:`interfaces` is offered on the transport; ``stop``
    withdraws them and releases the hardware or simulator (safe to call twice, and after a failed
    ``start``). Neither may block for long: a supervisor calls them on its main thread.
    """

    name: str

    def start(self) -> None:
        """Begin serving; raises a :class:`~kinema.errors.DriverError` when the driver cannot run."""
        ...

    def stop(self) -> None:
        """Stop serving and release resources."""
        ...

    def interfaces(self) -> list[ServedInterface]:
        """Everything this driver offers while it runs."""
        ...
