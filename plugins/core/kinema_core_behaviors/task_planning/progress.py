"""Publish a task's planning progress (``kinema_msgs/TaskPlanningStatus`` on ``/kinema/task_planning``).

PlanMTCTask hands the task planner's stage reports to a :class:`TaskProgress`; it publishes one message
when a stage changes state, a few times a second while a stage plans (so the time shown keeps running),
and one when the task is solved or has failed. The TUI's task panel shows the latest.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Sequence
from typing import Any

from kinema.ui_topics import TASK_PLANNING_TOPIC, TASK_PLANNING_TYPE

#: Seconds between messages while nothing changes but the running stage's time.
REFRESH_PERIOD_S = 0.25


class TaskProgress:
    """The progress of one planning run of ``task_id`` by the node at ``node_path``.

    Without a transport node (offline tests) nothing is published. Thread-safe: the planner reports from
    the behavior's worker thread, the refresh runs on its own.
    """

    def __init__(self, behavior: Any, task_id: str, node_path: str) -> None:
        node = behavior.context.node
        self._publisher = (
            None
            if node is None
            else behavior.context.publisher(node, TASK_PLANNING_TYPE, TASK_PLANNING_TOPIC)
        )
        self.task_id = task_id
        self.node_path = node_path
        self._began = time.monotonic()
        self._lock = threading.Lock()
        self._reports: Sequence[Any] = ()
        self._reported_at = self._began
        self._done = threading.Event()
        self._finished = False
        self._refresher: threading.Thread | None = None

    def __enter__(self) -> TaskProgress:
        if self._publisher is not None:
            self._refresher = threading.Thread(target=self._refresh, name="task-progress", daemon=True)
            self._refresher.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._done.set()
        if self._refresher is not None:
            self._refresher.join(timeout=1.0)

    def update(self, reports: Sequence[Any]) -> None:
        """The planner's callback: every stage's report after a change."""
        with self._lock:
            self._reports = tuple(reports)
            self._reported_at = time.monotonic()
        self._publish("planning")

    def finish(self, state: str, reports: Sequence[Any], message: str = "") -> None:
        """The task is ``solved`` or ``failed`` (``message`` says why); publish the final status."""
        self._done.set()
        with self._lock:
            self._reports = tuple(reports)
            self._reported_at = time.monotonic()
        self._publish(state, message)

    def _refresh(self) -> None:
        while not self._done.wait(REFRESH_PERIOD_S):
            self._publish("planning")

    def _publish(self, state: str, message: str = "") -> None:
        if self._publisher is None:
            return
        from kinema.transport import from_dict

        with self._lock:
            if self._finished or (state == "planning" and not self._reports):
                return  # nothing to show yet, or the final status is out: a late refresh must not follow it
            now = time.monotonic()
            # A stage still planning has run since the planner's last report: show its time so far.
            running = now - self._reported_at if state == "planning" else 0.0
            stages = [
                {
                    "name": r.name,
                    "type": r.stage_type,
                    "kind": r.kind,
                    "state": r.status,
                    "seconds": float(r.seconds) + (running if r.status == "planning" else 0.0),
                    "comment": r.comment,
                }
                for r in self._reports
            ]
            body = {
                "task_id": self.task_id,
                "node_path": self.node_path,
                "state": state,
                "seconds": now - self._began,
                "message": message,
                "stages": stages,
            }
            self._publisher.publish(from_dict(TASK_PLANNING_TYPE, body))
            self._finished = state != "planning"
