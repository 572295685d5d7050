"""A client of the MuJoCo driver's own services (free bodies, keyframes, setting the state).

For the controllers use the ros2_control-like actions and services directly (their names are in
:mod:`kinema.drivers.mujoco.names`); this covers what is specific to the simulator::

    client = SimClient(node)
    sim_time, bodies = client.bodies()
    client.set_state(keyframe="default")
    client.set_state(positions={"elbow_joint": 1.2})
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from kinema.drivers.mujoco import names
from kinema.errors import DriverError, TransportError
from kinema.transport import Node


@dataclass(frozen=True)
class SimBody:
    """A free body of the running simulation: world ``position`` (m) and ``orientation`` (x, y, z, w)."""

    name: str
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]

    def to_json(self) -> dict[str, Any]:
        """``{"name", "position": [x, y, z], "orientation": [x, y, z, w]}``."""
        return {"name": self.name, "position": list(self.position), "orientation": list(self.orientation)}


class SimClient:
    """Calls the driver's ``/mujoco/*`` services through ``node``.

    Args:
        node: the transport node to call from.
        timeout: seconds to wait for each answer (and for a driver to be found).
    """

    def __init__(self, node: Node, timeout: float = 5.0) -> None:
        self.node = node
        self.timeout = timeout
        self._clients: dict[str, Any] = {}

    def bodies(self) -> tuple[float, list[SimBody]]:
        """Sim time and the free bodies with their world poses."""
        response = self._call(names.BODIES_TYPE, names.BODIES_SERVICE, {})
        stamp = response.stamp.sec + response.stamp.nanosec * 1e-9
        bodies = []
        for body in response.bodies:
            p, q = body.pose.position, body.pose.orientation
            bodies.append(SimBody(str(body.name), (p.x, p.y, p.z), (q.x, q.y, q.z, q.w)))
        return stamp, bodies

    def keyframes(self) -> tuple[list[str], str]:
        """The model's keyframe names and the one the simulation started from ("" for none)."""
        response = self._call(names.KEYFRAMES_TYPE, names.KEYFRAMES_SERVICE, {})
        return [str(name) for name in response.names], str(response.initial)

    def set_state(
        self,
        keyframe: str = "",
        positions: Mapping[str, float] | None = None,
        velocities: Mapping[str, float] | None = None,
    ) -> str:
        """Reset to ``keyframe`` and/or set joint ``positions`` (and ``velocities``); return what was done.

        Raises:
            DriverError: the driver refused (unknown keyframe or joint, position out of range) or no
                driver answered.
        """
        positions = dict(positions or {})
        joint_state: dict[str, Any] = {
            "name": list(positions),
            "position": [float(v) for v in positions.values()],
        }
        if velocities:
            joint_state["velocity"] = [float(velocities.get(name, 0.0)) for name in positions]
        response = self._call(
            names.SET_STATE_TYPE, names.SET_STATE_SERVICE, {"keyframe": keyframe, "joint_state": joint_state}
        )
        if not response.success:
            raise DriverError(f"the simulator refused to set the state: {response.message}")
        return str(response.message)

    def _call(self, type_name: str, service: str, request: dict[str, Any]) -> Any:
        client = self._clients.get(service)
        if client is None:
            client = self._clients[service] = self.node.create_client(type_name, service)
        try:
            return client.call(request, timeout=self.timeout)
        except TransportError as error:
            raise DriverError(
                f"no MuJoCo driver answered at {service} ({error}); is the simulation running (`kinema run`)?"
            ) from error
