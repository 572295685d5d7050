"""Errors of the behavior-tree engine, mirroring BT.CPP's exception types.

BT.CPP distinguishes ``LogicError`` (a programming or model mistake, e.g. a port that cannot be
converted) from ``RuntimeError`` (something that went wrong while building or ticking), and wraps any
exception thrown by a node's ``tick()`` once as ``NodeExecutionError`` naming the innermost node.
All of them are :class:`kinema.errors.ObjectiveError`, so the CLI renders them as one line.
"""

from __future__ import annotations

from kinema.errors import ObjectiveError, SourceLocation


class BTError(ObjectiveError):
    """Base class of the engine's errors (BT.CPP ``BehaviorTreeException``).

    ``message`` is BT.CPP's ``what()`` text; rendered with its location (``file:line: ...``), the line
    that text starts with ("Error at line 4: -> ") is not said twice.
    """

    btcpp_type = "BehaviorTreeException"

    def __str__(self) -> str:
        location = self.location
        if location is not None and location.line:
            prefix = f"Error at line {location.line}: "
            if self.message.startswith(prefix):
                return f"{location}: {self.message[len(prefix) :].removeprefix('-> ')}"
        return super().__str__()


class BTRuntimeError(BTError):
    """BT.CPP ``RuntimeError``: building or ticking a tree failed."""

    btcpp_type = "RuntimeError"


class BTLogicError(BTError):
    """BT.CPP ``LogicError``: the tree or a node type is used in a way that can never work."""

    btcpp_type = "LogicError"


class TreeNotFoundError(BTRuntimeError):
    """A tree (the one to create, or a ``<SubTree ID>``) is not loaded; ``tree_id`` names it."""

    def __init__(self, tree_id: str, message: str, *, location: SourceLocation | None = None) -> None:
        super().__init__(message, location=location)
        self.tree_id = tree_id


class ScriptError(BTRuntimeError):
    """A script failed to parse or to evaluate."""


class ScriptParseError(ScriptError):
    """A script has a syntax error (raised when the tree is built)."""


class NodeExecutionError(BTRuntimeError):
    """An exception escaped a node's ``tick()``; ``node_path`` names the innermost node."""

    def __init__(
        self,
        node_name: str,
        node_path: str,
        registration_id: str,
        message: str,
        *,
        location: SourceLocation | None = None,
    ) -> None:
        super().__init__(f"Exception in node '{node_path}' [{registration_id}]: {message}", location=location)
        self.node_name = node_name
        self.node_path = node_path
        self.registration_id = registration_id
        self.original_message = message
