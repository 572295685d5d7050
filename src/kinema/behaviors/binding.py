"""How a registered behavior class receives its context: a per-registry subclass.

The engine constructs nodes as ``cls(name, config)`` and knows nothing about robots. When a registry
populates a factory, each behavior class is wrapped in a thin subclass that carries the
:class:`BehaviorContext` and the plugin name as class attributes, and that names the behavior and the
plugin in any exception escaping ``tick`` or ``halt`` (``BaseException`` included: a ``SystemExit`` in a
behavior fails the objective, it does not end the runtime's tick thread). The author's class is never
modified, so the same class can be bound to several contexts at once (a running objective and the next
one).
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING, Any

from kinema.behaviors.cell_ports import cell_ports, resolve_cell_ports
from kinema.behaviors.faults import BehaviorExecutionError, behavior_fault
from kinema.bt import NodeStatus
from kinema.bt.errors import NodeExecutionError

if TYPE_CHECKING:
    from kinema.behaviors.context import BehaviorContext
    from kinema.plugins.registration import BehaviorRegistration


def bind_behavior(registration: BehaviorRegistration, context: BehaviorContext) -> type:
    """Return a subclass of ``registration.cls`` bound to ``context`` and stamped with its plugin."""
    base = registration.cls
    base_tick = base.tick  # type: ignore[attr-defined]
    base_halt = base.halt  # type: ignore[attr-defined]

    @functools.wraps(base_tick)
    def tick(self: Any) -> NodeStatus:
        try:
            return base_tick(self)
        except (NodeExecutionError, BehaviorExecutionError):
            raise
        except BaseException as error:
            # SystemExit, KeyboardInterrupt and GeneratorExit raised by behavior code are bugs like any
            # other: they fail the objective with the line that raised, never end the tick thread.
            raise behavior_fault(self, error, "tick") from error

    @functools.wraps(base_halt)
    def halt(self: Any) -> None:
        try:
            base_halt(self)
        except (NodeExecutionError, BehaviorExecutionError):
            raise
        except BaseException as error:
            raise behavior_fault(self, error, "halt") from error

    namespace: dict[str, Any] = {}
    declared = base.provided_ports()  # type: ignore[attr-defined]
    by_cell = cell_ports(declared)
    if by_cell:
        # The ports' defaults are this cell's values (kinema.behaviors.cell_ports); the config is read
        # when the factory registers the class, not per tick.
        resolved = resolve_cell_ports(declared, _cell_of(context))

        def provided_ports(cls: type) -> list[Any]:
            return list(resolved)

        namespace["provided_ports"] = classmethod(provided_ports)
        namespace["kinema_cell_ports"] = by_cell
    namespace |= {
        "__slots__": (),
        "__module__": base.__module__,
        "__qualname__": base.__qualname__,
        "__doc__": base.__doc__,
        "kinema_context": context,
        "kinema_plugin": registration.plugin,
        "tick": tick,
        "halt": halt,
    }
    return type(base.__name__, (base,), namespace)


def _cell_of(context: BehaviorContext) -> Any:
    """The context's cell settings; None when there are none or they cannot be read (the error shows
    where the settings are checked: ``kinema build`` and the runtime's start)."""
    from kinema.errors import ConfigError

    try:
        return context.cell
    except ConfigError:
        return None
