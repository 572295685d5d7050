"""At 80x24 a long objective's tree is taller than its pane: the view keeps the running node in sight,
until the user moves or scrolls (then it stays where they put it, until the next run)."""

from __future__ import annotations

from textual.pilot import Pilot
from tui_pilot_harness import drive, settle

from kinema.tui.connection import Heartbeat, NodeStatus, NodeStatusBatch, NodeStatusUpdate, ObjectiveSummary
from kinema.tui.fake_connection import FakeConnection
from kinema.tui.widgets.behavior_tree_view import BehaviorTreeView

STEPS = 40
LONG_XML = (
    '<root BTCPP_format="4" main_tree_to_execute="Long Line"><BehaviorTree ID="Long Line"><Sequence>'
    + "".join(f'<Action ID="AlwaysSuccess" name="step {i}"/>' for i in range(1, STEPS + 1))
    + "</Sequence></BehaviorTree></root>"
)


def running(step: int, *, start: bool = False) -> NodeStatusBatch:
    """Step ``step`` (uid step + 1) started, the one before it done; with ``start``, the sequence (uid 1)
    starts too (a run's first batch)."""
    updates = [NodeStatusUpdate(1, "", "Sequence", "", NodeStatus.RUNNING)] if start else []
    if step > 1:
        updates.append(NodeStatusUpdate(step, "", "AlwaysSuccess", f"step {step - 1}", NodeStatus.SUCCESS))
    updates.append(NodeStatusUpdate(step + 1, "", "AlwaysSuccess", f"step {step}", NodeStatus.RUNNING))
    return NodeStatusBatch("Long Line", tuple(updates))


def visible(view: BehaviorTreeView, label: str) -> bool:
    """Whether the tree line whose label starts like ``label`` is inside the view's window now."""
    top, height = view.scroll_offset.y, view.scrollable_content_region.height
    for line in range(top, top + height):
        node = view.get_node_at_line(line)
        if node is not None and label in str(node.label):
            return True
    return False


def test_the_tree_follows_the_running_node_until_the_user_scrolls() -> None:
    fake = FakeConnection(
        objectives=[ObjectiveSummary("Long Line", "", "Examples", True, False, "lab_sim", "long.xml")],
        xml={"Long Line": LONG_XML},
    )

    async def scenario(app, pilot: Pilot[None]) -> None:  # type: ignore[no-untyped-def]
        fake.emit(Heartbeat(10.0, "Long Line", "Running"))
        fake.emit(running(1, start=True))
        await settle(pilot)
        view = app.screen.query_one(BehaviorTreeView)
        assert view.scrollable_content_region.height < STEPS, "the pane must be shorter than the tree"
        assert visible(view, "“step 1”")
        fake.emit(running(35))
        await settle(pilot)
        assert visible(view, "“step 35”"), "the view did not follow the run"
        # The user looks at the top: the next steps do not pull the view away.
        view.focus()
        await settle(pilot)
        await pilot.press("home")
        await settle(pilot)
        fake.emit(running(36))
        await settle(pilot)
        assert not visible(view, "“step 36”") and view.scroll_offset.y == 0
        # A new run follows again.
        fake.emit(Heartbeat(20.0, "Long Line", "Idle"))
        fake.emit(Heartbeat(21.0, "Long Line", "Running"))
        fake.emit(running(30, start=True))
        await settle(pilot)
        assert visible(view, "“step 30”")

    drive(fake, scenario, size=(80, 24))
