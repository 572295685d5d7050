"""Asking the user: approvals and breakpoints, in the TUI when one is attached.

A UI that can ask the user serves ``/kinema/user_approval`` (``kinema_msgs/srv/RequestApproval``); the
TUI does while it is open. Behaviors find the user through that service:

- ``IsUserAvailable`` succeeds when such a UI is attached, so MoveIt Pro's "Wait for Trajectory Approval
  if User Available" skips the approval when nobody is there to give it.
- ``WaitForMTCSolutionApproval`` and ``BreakpointSubscriber`` ask the user and wait for the answer.

**Headless rule.** Without a UI, approvals are not invented: ``IsUserAvailable`` fails and an approval
behavior fails with a message saying no user is attached — unless the runtime runs with
``KINEMA_AUTO_APPROVE=1`` (``kinema run --auto-approve`` sets it), in which case every approval and
breakpoint is granted at once and a warning toast records that it was granted automatically. A
breakpoint also resumes on any message on its ``breakpoint_topic`` (``std_msgs/Empty``), as MoveIt Pro's
Resume button publishes.
"""

from __future__ import annotations

import os
import threading
import time
from typing import Any

from kinema.behaviors import AsyncBehavior, FormerSpelling, NodeStatus, PortInfo, StatefulBehavior, input_port
from kinema.errors import KinemaError, TransportError
from kinema.ui_topics import APPROVAL_SERVICE, APPROVAL_TYPE

from ..task_planning.solution_summary import show_solution, solution_steps

AUTO_APPROVE_ENV = "KINEMA_AUTO_APPROVE"
# How long IsUserAvailable looks for the UI's service on the graph.
DISCOVERY_SECONDS = 0.5
ANSWER_SECONDS = 3600.0


def auto_approve() -> bool:
    """True when the runtime was told to grant approvals without a user (``KINEMA_AUTO_APPROVE=1``)."""
    return os.environ.get(AUTO_APPROVE_ENV, "").strip().lower() in ("1", "true", "yes", "on")


def approval_client(behavior: Any) -> Any | None:
    """The approval service client of ``behavior``'s context, or None without a transport node."""
    node = behavior.context.node
    if node is None:
        return None
    return behavior.context.service_client(node, APPROVAL_TYPE, APPROVAL_SERVICE)


class IsUserAvailable(StatefulBehavior):
    """Succeeds when a user can answer (a TUI is attached), fails otherwise; see the headless rule.

    With ``KINEMA_AUTO_APPROVE=1`` it succeeds (the automatic approver counts as the user). It looks for
    the UI's service for up to half a second (discovery on a fresh connection takes a moment) without
    holding the tick thread.
    """

    subcategory = "User Input"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return []

    def __init__(self, name: str, config: Any = None) -> None:
        super().__init__(name, config)
        self._client: Any = None
        self._deadline = 0.0

    def on_start(self) -> NodeStatus:
        if auto_approve():
            return NodeStatus.SUCCESS
        self._client = approval_client(self)
        if self._client is None:
            return NodeStatus.FAILURE
        self._deadline = time.monotonic() + DISCOVERY_SECONDS
        return self.on_running()

    def on_running(self) -> NodeStatus:
        if self._client.service_is_ready():
            return NodeStatus.SUCCESS
        return NodeStatus.FAILURE if time.monotonic() >= self._deadline else NodeStatus.RUNNING

    def on_halted(self) -> None:
        self._client = None


class _AskUser(AsyncBehavior):
    """Ask the user through the approval service; the subclass gives the prompt."""

    def prompt(self) -> str:
        raise NotImplementedError

    def granted_without_user(self) -> bool:
        """Headless: grant when auto-approving (logged), else fail naming the rule."""
        if auto_approve():
            self.logger.publish_warn(f"{self.prompt()} — approved automatically ({AUTO_APPROVE_ENV}=1)")
            return True
        self.logger.publish_failure(
            f"{self.registration_id}: no user interface is attached to answer '{self.prompt()}'; open "
            f"`kinema ui`, or run headless with `kinema run --auto-approve` ({AUTO_APPROVE_ENV}=1)"
        )
        return False

    async def ask(self, details: dict[str, Any] | None = None) -> bool:
        """Ask the user; ``details`` adds request fields (the steps and duration of a motion)."""
        import asyncio

        client = approval_client(self)
        if client is None or not await asyncio.to_thread(client.wait_for_service, DISCOVERY_SECONDS):
            return self.granted_without_user()
        request = {
            "behavior": self.registration_id,
            "node_path": self.full_path,
            "prompt": self.prompt(),
            **(details or {}),
        }
        try:
            # The user may take their time (an hour at most); halting the node stops waiting for them.
            response = await asyncio.wrap_future(client.call_async(request, ANSWER_SECONDS))
        except TransportError as error:
            self.logger.publish_failure(f"{self.registration_id}: asking the user failed: {error.message}")
            return False
        if not response.approved:
            said = f": {response.message}" if str(response.message) else ""
            self.logger.publish_failure(f"{self.prompt()} — rejected by the user{said}")
            return False
        return True


class WaitForMTCSolutionApproval(_AskUser):
    """Asks the user to approve the planned ``solution`` and succeeds only if they do.

    The solution (an MTC solution or a joint trajectory) is drawn in ``kinema view`` while the question is
    open: its motion, and for an MTC solution each stage's tool path. The TUI's question lists the
    solution's motions (stage, duration, joints, what the gripper does) and its whole duration. See the
    headless rule above.
    """

    subcategory = "User Input"
    former_spellings = (FormerSpelling("WaitForUserTrajectoryApproval"),)

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "solution", None, "{solution}", "The planned solution (an MTC solution or trajectory)."
            ),
            input_port(
                "cartesian_path_links",
                list[str],
                "",
                "Robot links whose paths kinema view draws along the solution ('': for an MTC solution the "
                "tip of its group, stage by stage); a name that is no link is left out, with a warning.",
            ),
        ]

    def prompt(self) -> str:
        return "Approve the planned motion?"

    def _links(self, model: Any) -> list[str]:
        wanted = [str(v).strip() for v in self.get_input_or("cartesian_path_links", []) if str(v).strip()]
        if model is None:
            return []
        unknown = [link for link in wanted if link not in model.link_names]
        if unknown:
            from kinema.errors import did_you_mean

            self.logger.publish_warn(
                f"{self.registration_id}: cartesian_path_links names {unknown[0]!r}, which is no link of the "
                f"robot; its path is not drawn ({did_you_mean(unknown[0], model.link_names)})"
            )
        return [link for link in wanted if link in model.link_names]

    async def do_work(self) -> bool:
        solution = self.get_input_or("solution", None)
        try:
            model = self.context.robot_model
        except KinemaError as error:  # the question still goes out, without the gripper's changes
            self.logger.publish_warn(
                f"{self.registration_id}: no robot model to describe the motion: {error}"
            )
            model = None
        steps, duration = solution_steps(solution, model)
        show_solution(self, solution, model, self._links(model))
        return await self.ask({"steps": steps, "duration": duration} if steps else None)


class BreakpointSubscriber(_AskUser):
    """Pauses the objective until the user resumes it (TUI question, or a message on ``breakpoint_topic``).

    ``message`` is what the user is asked ("Approve satellite grappling"); the question then also names
    where the objective stopped. Headless with ``KINEMA_AUTO_APPROVE=1`` it resumes at once (logged);
    headless without it, it waits for a message on the topic, and its message says how to send one.
    """

    subcategory = "User Input"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port(
                "breakpoint_topic",
                str,
                "/moveit_pro_breakpoint",
                "Topic whose next message (std_msgs/Empty) resumes the objective.",
            ),
            input_port(
                "message",
                str,
                "",
                "What the user is asked before resuming (shown in the UI and logs); '': 'resume?'.",
            ),
        ]

    def prompt(self) -> str:
        message = str(self.get_input_or("message", "") or "").strip()
        if message:
            return f"{message} (breakpoint at {self.full_path})"
        return f"Breakpoint at {self.full_path}: resume?"

    async def do_work(self) -> bool:
        import asyncio

        node = self.context.require_node(self.registration_id)
        resumed = threading.Event()
        subscription = node.create_subscription(
            "std_msgs/msg/Empty", str(self.get_input("breakpoint_topic")), lambda _msg: resumed.set()
        )
        try:
            client = approval_client(self)
            if client is not None and await asyncio.to_thread(client.wait_for_service, DISCOVERY_SECONDS):
                asking = asyncio.ensure_future(self.ask())
                waiting = asyncio.ensure_future(asyncio.to_thread(resumed.wait))
                done, pending = await asyncio.wait({asking, waiting}, return_when=asyncio.FIRST_COMPLETED)
                for task in pending:
                    task.cancel()
                resumed.set()
                return bool(asking.result()) if asking in done else True
            if auto_approve():
                return self.granted_without_user()
            topic = str(self.get_input("breakpoint_topic"))
            self.logger.publish_info(
                f"{self.prompt()} No UI is attached: resume with `kinema topic pub --once {topic} "
                "std_msgs/msg/Empty`, or attach one (`kinema ui`); `kinema run --auto-approve` passes "
                "breakpoints by itself"
            )
            while not resumed.is_set():
                await asyncio.sleep(0.05)
            return True
        finally:
            resumed.set()
            subscription.close()
