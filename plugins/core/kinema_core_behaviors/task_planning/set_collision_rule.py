"""SetupMTCSetCollisionRule: a stage that allows (or forbids again) contact between two things."""

from __future__ import annotations

from typing import Any

from kinema.behaviors import FormerSpelling, PortInfo, input_port
from kinema.errors import KinemaError

from .mtc_task import MtcTask, stage_name
from .setup_stages import _SetupStage


def _names(behavior: Any, port: str) -> list[str]:
    text = str(behavior.get_input_or(port, "")).strip()
    names = [part.strip() for part in text.split(";") if part.strip()]
    if not names:
        raise KinemaError(f"port [{port}] is empty; name a robot link, a planning group or an object")
    return names


class SetupMTCSetCollisionRule(_SetupStage):
    """Adds a stage after which contact between ``name_a`` and ``name_b`` is allowed (``allow_collision``
    true) or checked again (false), for the task's later stages.

    A name is a robot link, a planning group whose links the SRDF lists (``gripper``), a planning-scene
    object (in the world or attached, a URDF tool included), or MoveIt's ``<octomap>`` (Kinema's point
    cloud obstacles, UpdatePlanningSceneService's object; nothing when there is none). Several names may
    be given separated by ``;``. The task fails to plan, naming the stage, when a name is none of these.
    The rule changes the task's planning only; the live planning scene is left as it is.
    """

    # MoveIt Pro 9.4 folded its group/object collision-rule stages into this one (its migration guide).
    former_spellings = (
        FormerSpelling(
            "SetupMTCUpdateGroupCollisionRule",
            ports={"group_name": "name_a", "object_name": "name_b"},
            dropped={"parameters": "the rule's settings are its ports (name_a, name_b, allow_collision)"},
        ),
    )

    @classmethod
    def stage_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "name_a", str, "", "One side: link, planning group or object (';' separates several)."
            ),
            input_port("name_b", str, "", "The other side: link, group, object or <octomap>."),
            input_port(
                "allow_collision",
                bool,
                True,
                "true: contact is allowed from this stage on; false: it is checked again.",
            ),
        ]

    def stage(self, task: MtcTask) -> Any:
        from kinema.motion.task_stages import AllowCollisions

        allow = bool(self.get_input("allow_collision"))
        return AllowCollisions(
            _names(self, "name_a"),
            _names(self, "name_b"),
            allow,
            name=stage_name(task, "allow collisions" if allow else "forbid collisions"),
        )
