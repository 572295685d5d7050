"""What every Kinema behavior shares: metadata, the context, the logger, required inputs.

:class:`Behavior` is a mixin; authors derive from one of the concrete bases
(:class:`~kinema.behaviors.SyncBehavior`, :class:`~kinema.behaviors.AsyncBehavior`, ...), which combine
it with the matching engine node type.
"""

from __future__ import annotations

import inspect
import re
from builtins import type as type_of
from typing import Any, ClassVar

from kinema.behaviors.context import BehaviorContext
from kinema.behaviors.logger import BehaviorLogger
from kinema.behaviors.required_inputs import get_required_inputs
from kinema.bt.spellings import FormerSpelling

_OFFLINE_CONTEXT: BehaviorContext | None = None


def _offline_context() -> BehaviorContext:
    global _OFFLINE_CONTEXT
    if _OFFLINE_CONTEXT is None:
        _OFFLINE_CONTEXT = BehaviorContext.offline()
    return _OFFLINE_CONTEXT


class Behavior:
    """Mixin giving a BT node Kinema's behavior services.

    Class attributes:
        subcategory: where editors and ``kinema behaviors`` group it (MoveIt Pro's ``subcategory``).
        description: one paragraph for editors; defaults to the first paragraph of the docstring.
        former_spellings: old IDs and port names objectives may still use, read as this behavior's
            (:class:`~kinema.bt.FormerSpelling`); only the class's own value counts, not a base's.
    """

    __slots__ = ()

    subcategory: ClassVar[str] = "User Created Behaviors"
    description: ClassVar[str] = ""
    former_spellings: ClassVar[tuple[FormerSpelling, ...]] = ()

    # Set on the per-registry subclass made by kinema.behaviors.binding (never by authors).
    kinema_context: ClassVar[BehaviorContext | None] = None
    kinema_plugin: ClassVar[str] = ""
    # Port name -> (cell value key, empty reads as default), for ports declared with cell_input_port
    # (set by the binding).
    kinema_cell_ports: ClassVar[dict[str, tuple[str, bool]]] = {}

    def get_input(self, name: str, type: Any = None) -> Any:
        """The value of input port ``name`` (see the engine's ``TreeNode.get_input``).

        A port declared with :func:`~kinema.behaviors.cell_ports.cell_input_port` that is empty or
        missing reads as the cell's configured value; without one it fails naming the config key to set.
        """
        found = type_of(self).kinema_cell_ports.get(name)
        if found is None:
            return super().get_input(name, type)  # type: ignore[misc]
        cell_key, empty_is_default = found
        from kinema.bt.node import PortError

        try:
            value = super().get_input(name, type)  # type: ignore[misc]
        except PortError:
            value = None
        if value is not None and (value != "" or not empty_is_default):
            return value
        context = self.context
        from kinema.behaviors.cell_ports import missing_cell_value_message
        from kinema.errors import ConfigError

        try:
            cell = context.cell
        except ConfigError as error:
            raise PortError(f"port [{name}]: the config's robot settings are wrong: {error}") from None
        resolved = cell.value(cell_key) if cell is not None else None
        if resolved is None:
            config = getattr(context.config, "name", None)
            raise PortError(
                f"node '{self.full_path}': {missing_cell_value_message(name, cell_key, config)}"  # type: ignore[attr-defined]
            )
        return resolved

    @classmethod
    def metadata(cls) -> dict[str, str]:
        """The behavior's metadata as MoveIt Pro names it (``subcategory``, ``description``).

        Called when the behavior is registered and when models are exported; must not depend on an
        instance.
        """
        description = cls.description
        if not description:
            doc = inspect.getdoc(cls) or ""
            # A docstring's reST literals (``name``) read as `name` where descriptions are shown: the
            # terminal UI, `kinema behaviors`, Groot2's palette.
            summary = doc.split("\n\n", 1)[0].replace("\n", " ").strip()
            description = re.sub(r"``(.+?)``", r"`\1`", summary)
        return {"subcategory": cls.subcategory, "description": description}

    @property
    def context(self) -> BehaviorContext:
        """The shared context (transport node, clock, robot model, log sink) of the tree."""
        context = type(self).kinema_context
        return context if context is not None else _offline_context()

    @property
    def logger(self) -> BehaviorLogger:
        """This node's logger: ``publish_info/publish_warn/publish_failure`` become toasts."""
        # Kept in the instance dict (TreeNode has one) because a mixin combined with a slotted node
        # class cannot declare slots of its own.
        logger: BehaviorLogger | None = self.__dict__.get("_kinema_logger")
        if logger is None:
            logger = self.__dict__["_kinema_logger"] = self.context.logger_for(
                behavior_id=str(getattr(self, "registration_id", type(self).__name__)),
                node_name=str(getattr(self, "name", "")),
                node_path=str(getattr(self, "full_path", "")),
                plugin=type(self).kinema_plugin,
            )
        return logger

    def get_required_inputs(self, *names: str) -> tuple[Any, ...]:
        """Return the values of the input ports ``names``, or raise one error naming every missing one.

        Raises:
            MissingInputsError: one or more ports have no value; catch it, ``publish_failure`` its
                message and return FAILURE, or let it fail the objective.
        """
        return get_required_inputs(self, *names)
