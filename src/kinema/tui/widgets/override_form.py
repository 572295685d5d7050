"""A form of parameter overrides built from an objective's ports: one input per input/inout port.

The ports are the runtime's list of the objective's parameters (:mod:`kinema.config.objective_parameters`),
the same as ``kinema objective show`` and the SDK's ``parameters()`` give.
"""

from __future__ import annotations

from textual.app import ComposeResult
from textual.containers import VerticalScroll
from textual.widget import Widget
from textual.widgets import Input, Label, Static

from kinema.tui.connection import ObjectiveSummary


class OverrideForm(VerticalScroll):
    """Inputs for the objective's input ports; an empty input keeps the port's default."""

    DEFAULT_CSS = """
    OverrideForm { height: 1fr; }
    OverrideForm .port-label { margin-top: 1; }
    OverrideForm .port-help { color: $text-muted; }
    """

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__(id=id)
        self.objective: ObjectiveSummary | None = None

    def compose(self) -> ComposeResult:
        yield Static("Select an objective to see its parameters.", classes="port-help")

    async def show_objective(self, objective: ObjectiveSummary | None) -> None:
        """Rebuild the form for ``objective``'s ports."""
        self.objective = objective
        await self.remove_children()
        if objective is None:
            await self.mount(Static("Select an objective to see its parameters.", classes="port-help"))
            return
        ports = [p for p in objective.ports if p.direction in ("input", "inout")]
        if not ports:
            await self.mount(Static(f"{objective.name} takes no parameters.", classes="port-help"))
            return
        widgets: list[Widget] = [
            Static(
                "Values are YAML, parsed into each port's type. Empty keeps the default.", classes="port-help"
            )
        ]
        for port in ports:
            kind = f"{port.type_name}, {port.direction}" if port.type_name else port.direction
            widgets.append(Label(f"{port.name} ({kind})", classes="port-label"))
            if port.description:
                widgets.append(Static(port.description, classes="port-help"))
            widgets.append(
                Input(
                    placeholder=f"default: {port.default}" if port.default else "no default",
                    id=f"port-{_safe_id(port.name)}",
                    name=port.name,
                )
            )
        await self.mount_all(widgets)

    def overrides(self) -> dict[str, str]:
        """Port name -> value for every filled-in input."""
        return {
            field.name: field.value.strip()
            for field in self.query(Input)
            if field.name is not None and field.value.strip()
        }


def _safe_id(name: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_" else "_" for ch in name)
