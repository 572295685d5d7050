"""A behavior's approval question appears as a dialog in the TUI, and the user's answer goes back."""

from __future__ import annotations

from typing import Any

from tui_pilot_harness import drive, settle

from kinema.tui.connection import ApprovalRequested
from kinema.tui.dialogs.confirm import ConfirmDialog
from kinema.tui.fake_connection import FakeConnection


def test_the_user_approves_or_declines_in_a_dialog(fake: FakeConnection) -> None:
    answers: list[tuple[bool, str]] = []

    def ask(prompt: str) -> ApprovalRequested:
        return ApprovalRequested(
            prompt, "WaitForMTCSolutionApproval", "Main/Approve", lambda *a: answers.append(a)
        )

    async def scenario(app: Any, pilot: Any) -> None:
        fake.emit(ask("Approve the planned motion?"))
        await settle(pilot)
        assert isinstance(app.screen, ConfirmDialog)
        assert "Approve the planned motion?" in app.screen.question
        assert "WaitForMTCSolutionApproval at Main/Approve" in app.screen.question
        await pilot.press("y")
        await settle(pilot)
        assert answers == [(True, "")]
        fake.emit(ask("Breakpoint at Main/Stop: resume?"))
        await settle(pilot)
        await pilot.press("n")
        await settle(pilot)
        assert answers[-1] == (False, "declined in the TUI")
        assert not isinstance(app.screen, ConfirmDialog)

    drive(fake, scenario)


def test_an_attached_tui_is_the_user_the_approval_behaviors_ask(monkeypatch: Any) -> None:
    """End to end over a router: the TUI's connection serves the approval service; a behavior asks it."""
    from kinema.behaviors import BehaviorContext
    from kinema.bt import NodeStatus
    from kinema.plugins import BehaviorHost
    from kinema.testing import tick_behavior
    from kinema.transport import Node, free_endpoint, host_router, open_session
    from kinema.tui.sdk_connection import SdkConnection

    monkeypatch.delenv("KINEMA_AUTO_APPROVE", raising=False)
    endpoint = free_endpoint()
    router = host_router(endpoint)
    connection = SdkConnection(endpoint, config="lab_sim")
    asked: list[str] = []

    def listener(event: Any) -> None:
        if isinstance(event, ApprovalRequested):
            asked.append(event.prompt)
            event.answer(False, "not now")

    session = open_session(endpoint)
    try:
        connection.open(listener)
        node = Node(session, "approval_test")
        client = node.create_client("kinema_msgs/srv/RequestApproval", "/kinema/user_approval")
        assert client.wait_for_service(20.0), "the TUI connection did not serve /kinema/user_approval"
        host = BehaviorHost(["kinema::CoreBehaviorsLoader"])
        host.load().raise_for_errors()
        context = BehaviorContext(node)
        available = tick_behavior(host.registry["IsUserAvailable"].cls, {}, context=context)
        assert available.status == NodeStatus.SUCCESS
        run = tick_behavior(
            host.registry["WaitForMTCSolutionApproval"].cls, {"solution": "plan"}, context=context
        )
        assert asked == ["Approve the planned motion?"]
        assert run.status == NodeStatus.FAILURE and "rejected by the user: not now" in run.toasts[-1]
        context.close()
    finally:
        connection.close()
        session.close()
        router.close()
