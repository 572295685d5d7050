"""ResetMujocoKeyframe: put the whole simulated scene back into one of its MJCF keyframes."""

from __future__ import annotations

from kinema.behaviors import AsyncBehavior, PortInfo, input_port
from kinema.drivers.mujoco.names import SET_STATE_SERVICE
from kinema.errors import TransportError

SERVICE_TYPE = "kinema_msgs/srv/SetMujocoState"


class ResetMujocoKeyframe(AsyncBehavior):
    """Resets the simulation to keyframe ``keyframe_name`` of its MJCF scene: the robot's joints, the free
    objects, velocities and actuators, as the keyframe has them.

    An empty name is the config's own keyframe (``hardware.simulation.mujoco_keyframe``, or MoveIt Pro's
    ``urdf_params: mujoco_keyframe``). Sim time keeps running; motions in progress are aborted and the
    controllers hold the new state. Fails when no simulator answers (``wait_for_server_available_timeout``),
    it does not answer in ``response_timeout``, or the keyframe does not exist (the simulator names those
    there are).
    """

    subcategory = "MuJoCo Simulation"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "keyframe_name",
                str,
                "",
                "The MJCF keyframe ('': the config's hardware.simulation.mujoco_keyframe).",
            ),
            input_port("response_timeout", float, 10.0, "Seconds to wait for the simulator's answer."),
            input_port(
                "wait_for_server_available_timeout",
                float,
                3.0,
                "Seconds to wait for the simulator's SetMujocoState service to be there.",
            ),
        ]

    async def do_work(self) -> bool:
        import asyncio

        keyframe = str(self.get_input_or("keyframe_name", "")).strip()
        if not keyframe:
            config = self.context.config
            keyframe = (config.mujoco_keyframe if config is not None else None) or ""
            if not keyframe:
                where = f"config {config.name!r}" if config is not None else "no config"
                self.logger.publish_failure(
                    f"ResetMujocoKeyframe: keyframe_name is empty and {where} names no keyframe; give "
                    "keyframe_name or set hardware.simulation.mujoco_keyframe"
                )
                return False
        node = self.context.require_node(self.registration_id)
        client = self.context.service_client(node, SERVICE_TYPE, SET_STATE_SERVICE)
        wait = float(self.get_input("wait_for_server_available_timeout"))
        if not await asyncio.to_thread(client.wait_for_service, max(wait, 0.0)):
            self.logger.publish_failure(
                f"ResetMujocoKeyframe: no simulator serves {SET_STATE_SERVICE} within {wait:g} s "
                "(wait_for_server_available_timeout); is `kinema run` simulating?"
            )
            return False
        try:
            response = await asyncio.wrap_future(
                client.call_async({"keyframe": keyframe}, float(self.get_input("response_timeout")))
            )
        except TransportError as error:
            self.logger.publish_failure(f"ResetMujocoKeyframe: calling {SET_STATE_SERVICE} failed: {error}")
            return False
        if not response.success:
            self.logger.publish_failure(f"ResetMujocoKeyframe: the simulator refused: {response.message}")
            return False
        return True
