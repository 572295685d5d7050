"""ValidateTrajectory: check a trajectory against the joint limits and the planning scene."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

from kinema.behaviors import AsyncBehavior, PortInfo, input_port, output_port
from kinema.behaviors.cell_ports import cell_input_port
from kinema.errors import KinemaError, did_you_mean

from ..messages.conversions import TRAJECTORY_TYPE, trajectory_from_message
from ..messages.ports import fails_on_bad_input, message_input, port_error, read_message
from .joint_states import joint_state_monitor
from .planning_resources import collision_checker, robot_model

# A state this far past a limit (rad or m) still counts as inside it: YAML round trips and the
# simulation's contact solver leave values a few micro-units past a stop.
_LIMIT_TOLERANCE = 1e-6


class ValidateTrajectory(AsyncBehavior):
    """Succeeds when every state along ``joint_trajectory_msg`` is inside the joint limits and free of
    collisions with the robot itself and the current planning scene.

    The path is checked at least every ``joint_space_step`` (rad or m per joint) and every
    ``cartesian_space_step`` metres of the tip of ``planning_group_name``. Joints of the robot the
    trajectory does not move stay where they are now. Fails naming the first bad time and what collides
    or which limit is crossed. ``planning_scene_msg`` is accepted as in MoveIt Pro; the check uses the
    runtime's planning scene, which is what it describes.
    """

    subcategory = "Motion - Planning"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "joint_trajectory_msg", TRAJECTORY_TYPE, "{joint_trajectory_msg}", "The trajectory to check."
            ),
            cell_input_port(
                "planning_group_name",
                str,
                "planning_group",
                "The group whose tip the Cartesian step measures.",
            ),
            input_port(
                "joint_space_step", float, 0.1, "Largest joint change between checked states (rad or m)."
            ),
            input_port("cartesian_space_step", float, 0.02, "Largest tip motion between checked states (m)."),
            input_port(
                "planning_scene_msg",
                None,
                "{planning_scene}",
                "The planning scene (from GetCurrentPlanningScene).",
            ),
            output_port(
                "debug_solution", None, "{debug_solution}", "The checked trajectory, for display or approval."
            ),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        import numpy as np

        from kinema.motion import fk

        message = read_message(self, "joint_trajectory_msg")
        try:
            trajectory = trajectory_from_message(message, "joint_trajectory_msg")
        except KinemaError as error:
            raise port_error(self, "joint_trajectory_msg", str(error)) from None
        joint_step = float(self.get_input("joint_space_step"))
        cartesian_step = float(self.get_input("cartesian_space_step"))
        for port, value in (("joint_space_step", joint_step), ("cartesian_space_step", cartesian_step)):
            if not value > 0:
                raise port_error(self, port, f"= {value:g}", "expected a step > 0")
        group_name = str(self.get_input("planning_group_name"))
        try:
            model = robot_model(self.context, "ValidateTrajectory")
            if group_name not in model.groups:
                raise port_error(
                    self,
                    "planning_group_name",
                    f"= {group_name!r}",
                    did_you_mean(group_name, list(model.groups)),
                )
            unknown = [n for n in trajectory.joint_names if n not in model.joint_names]
            if unknown:
                raise port_error(
                    self,
                    "joint_trajectory_msg",
                    f"moves unknown joint(s) {', '.join(unknown)}",
                    f"valid: {', '.join(model.joint_names)}",
                )
            # Joints the trajectory does not move keep their current values, clipped into the limits: a
            # simulated finger resting a hair past its stop does not make the file's trajectory invalid.
            base = np.clip(
                joint_state_monitor(self.context, "ValidateTrajectory").positions(model.joint_names),
                model.lower,
                model.upper,
            )
            checker = collision_checker(self.context, "ValidateTrajectory", 0.0)
        except KinemaError as error:
            if type(error).__name__ == "PortValueError":
                raise
            return self._fail(str(error))
        columns = [model.joint_names.index(n) for n in trajectory.joint_names]
        tip = model.group(group_name).tip_link
        data = model.new_data()
        previous_q: np.ndarray | None = None
        previous_tip: np.ndarray | None = None
        for i, row in enumerate(trajectory.positions):
            q = base.copy()
            q[columns] = row
            if previous_q is not None:
                steps = int(np.ceil(np.abs(q - previous_q).max() / joint_step))
                if tip is not None and previous_tip is not None:
                    moved = float(np.linalg.norm(fk(model, q, tip, data)[:3, 3] - previous_tip))
                    steps = max(steps, int(np.ceil(moved / cartesian_step)))
                for s in range(1, max(1, steps) + 1):
                    sample = previous_q + (q - previous_q) * (s / max(1, steps))
                    problem = self._problem(checker, model, sample)
                    if problem:
                        return self._fail(
                            f"the state between t={trajectory.times[i - 1]:.3f} s and "
                            f"t={trajectory.times[i]:.3f} s {problem}"
                        )
            else:
                problem = self._problem(checker, model, q)
                if problem:
                    return self._fail(f"the first state (t=0) {problem}")
            previous_q = q
            previous_tip = fk(model, q, tip, data)[:3, 3] if tip is not None else None
            if self.stop_requested():
                return False
        self.set_output("debug_solution", message)
        return True

    @staticmethod
    def _problem(checker: Any, model: Any, q: np.ndarray) -> str:
        if not model.within_limits(q, _LIMIT_TOLERANCE):
            outside = [
                f"{n}={v:.6g} (limits {lo:.6g}..{hi:.6g})"
                for n, v, lo, hi in zip(model.joint_names, q, model.lower, model.upper, strict=True)
                if not lo - _LIMIT_TOLERANCE <= v <= hi + _LIMIT_TOLERANCE
            ]
            return "is outside the joint limits: " + ", ".join(outside)
        if checker.in_collision(q):
            return f"is in collision: {checker.describe(q)}"
        return ""

    def _fail(self, reason: str) -> bool:
        self.logger.publish_failure(f"ValidateTrajectory: trajectory is not valid: {reason}")
        return False
