"""Find which behavior a thread is stuck in, and say so in one sentence.

The objective server's watchdog uses it to report a tick that does not return ("behavior 'Block'
(Root/block) has been in tick for 3.0 s") without costing the tick path anything: nothing is recorded
while nodes run; the stuck thread's stack is read only when a tick overruns. The innermost frame whose
``self`` is a behavior tree node names the behavior, its node path and the method it is in.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass


@dataclass(frozen=True)
class StuckCode:
    """Where a thread is: the node whose code runs and the method it is in.

    Attributes:
        behavior: the node's registration ID (``Block``), or "" when no node is on the stack.
        node_path: the node's full path in its tree.
        method: the method of the node the thread is in (``tick``, ``on_running``, ``halt``...), or
            what the server was doing when no node is on the stack.
    """

    behavior: str
    node_path: str
    method: str

    def describe(self, seconds: float) -> str:
        """``behavior 'X' (path) has been in tick for N s``."""
        if self.behavior:
            who = f"behavior '{self.behavior}' ({self.node_path})"
        else:
            who = "the objective server"
        return f"{who} has been in {self.method} for {seconds:.1f} s"


def stuck_code(thread_id: int | None, fallback: str) -> StuckCode:
    """Read the stack of thread ``thread_id`` and name the innermost behavior tree node on it.

    ``fallback`` is what the thread was doing (``tick``, ``halt``, ``build``), used when no node is on
    its stack (a behavior's constructor, a hot-reload swap) or the thread is gone.
    """
    from kinema.bt.node import TreeNode

    frame = sys._current_frames().get(thread_id) if thread_id is not None else None
    while frame is not None:
        owner = frame.f_locals.get("self")
        if isinstance(owner, TreeNode):
            try:
                path = str(owner.full_path)
            except AttributeError:  # a node still being built has no config (path) yet
                path = ""
            return StuckCode(
                str(getattr(owner, "registration_id", type(owner).__name__)),
                path,
                _method_name(frame.f_code.co_name, fallback),
            )
        frame = frame.f_back
    return StuckCode("", "", fallback)


def _method_name(name: str, fallback: str) -> str:
    # execute_tick and the engine's private helpers are the engine around the node, not its own code.
    if name.startswith("_") or name == "execute_tick":
        return fallback
    return name
