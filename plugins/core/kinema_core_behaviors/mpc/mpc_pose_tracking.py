"""MPCPoseTracking: model predictive control that keeps a frame of the robot on a moving target pose."""

from __future__ import annotations

from kinema.behaviors import PortInfo, input_port

from .control_loop import MpcControlLoop, common_ports


class MPCPoseTracking(MpcControlLoop):
    """Tracks ``target_pose`` with ``gripper_site_name`` by model predictive control until halted.

    Every ``timestep`` a QP plans the next ``horizon`` seconds of joint motion that brings the frame
    onto the target (expected to move on at ``target_twist``) within the joints' position, velocity and
    acceleration limits and the Cartesian speed limit, and the plan goes to the trajectory controller
    (see :mod:`.control_loop` for the loop, the controller and what each MoveIt Pro port does here).
    RUNNING until halted; SUCCESS after ``timeout`` seconds. Halting stops the arm. Fails, stopping the
    arm, on an unknown group or frame (naming the valid ones), a target that is not a PoseStamped, no
    joint states, or a QP without solution.

    Where MoveIt Pro's semantics are not public (its planner samples trajectories on a MuJoCo model and
    weighs residuals): Kinema's weights ``site_tracking``, ``velocity`` and ``acceleration`` are costs of a
    QP, the Cartesian speed and joint limits are hard constraints, and the sampler's tuning ports are
    accepted and unused. Port defaults are the values lab_sim's MPC objectives give.
    """

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            *common_ports(horizon=0.2, site_tracking=1.0, warmup=64),
            input_port(
                "force_torque",
                float,
                0.0,
                "MoveIt Pro's weight of a force/torque cost; Kinema's MPC has no force model (a value "
                "other than 0 is reported and has no effect).",
            ),
        ]
