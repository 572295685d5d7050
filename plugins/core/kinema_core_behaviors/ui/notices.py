"""SwitchUIPrimaryView: MoveIt Pro switches its main pane; Kinema's TUI shows it as a notice."""

from __future__ import annotations

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port


class SwitchUIPrimaryView(SyncBehavior):
    """Tells the user which view to look at (a notice in the TUI; the 3D view is ``kinema view``).

    Kinema's UIs have no switchable primary pane, so the request becomes an info toast naming the view.
    """

    subcategory = "User Interface"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("primary_view_name", str, "Visualization", "The view (pane or image topic) to show.")
        ]

    def tick(self) -> NodeStatus:
        view = str(self.get_input_or("primary_view_name", "Visualization"))
        where = "the 3D view (kinema view)" if view == "Visualization" else repr(view)
        self.logger.publish_info(f"Look at {where}")
        return NodeStatus.SUCCESS
