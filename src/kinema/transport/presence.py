"""A Kinema process's presence on the network: who is the agent, who the drivers of a cell.

Each agent and driver process declares a **presence token** (a zenoh liveliness token, like the ROS graph's),
``@kinema_lv/<domain>/<zid>/<role>/<name>/<pid>/<parent pid>/<host>/<config>/<endpoint>``, which disappears
when the process does. The runtime reads them to keep one agent and one set of drivers per cell
(:mod:`kinema.runtime.cell`); the drivers only declare theirs, so this lives below both.
"""

from __future__ import annotations

import os
import socket
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any
from urllib.parse import quote, unquote

if TYPE_CHECKING:
    from kinema.transport.session import Session

__all__ = [
    "AGENT",
    "DRIVER",
    "PRESENCE_PREFIX",
    "ROLES",
    "Member",
    "declare_presence",
    "parse_presence",
    "presence_key",
    "query_presences",
]

PRESENCE_PREFIX = "@kinema_lv"
# What a process is to its cell.
AGENT, DRIVER = "agent", "driver"
ROLES = (AGENT, DRIVER)


@dataclass(frozen=True)
class Member:
    """An agent or driver process seen on the network.

    Attributes:
        role: ``agent`` or ``driver``.
        zid: its zenoh session id.
        name: the driver's name (``mujoco``) or ``agent``; empty when only the ROS graph showed it.
        pid: its process id (None when unknown: no presence token).
        parent_pid: the ``kinema run`` supervisor that started it (None when unknown).
        host: the machine's host name.
        config: the config package it runs.
        endpoint: the router endpoint it joined.
    """

    role: str
    zid: str
    name: str = ""
    pid: int | None = None
    parent_pid: int | None = None
    host: str = ""
    config: str = ""
    endpoint: str = ""

    def describe(self) -> str:
        """One phrase for messages: ``agent of config lab_sim (pid 12, host robot, kinema run pid 10)``."""
        what = self.role if self.role == AGENT or not self.name else f"driver {self.name!r}"
        if self.pid is None:
            return f"{what} (zenoh id {self.zid[:12]}; not a Kinema process or an older one)"
        details = [f"pid {self.pid}"]
        if self.host:
            details.append(f"host {self.host}")
        if self.parent_pid:
            details.append(f"started by pid {self.parent_pid}")
        config = f" of config {self.config}" if self.config else ""
        return f"{what}{config} ({', '.join(details)})"


def _chunk(text: str) -> str:
    return quote(text, safe="") or "%"


def _unchunk(text: str) -> str:
    return "" if text == "%" else unquote(text)


def presence_key(session: Session, member: Member) -> str:
    """The liveliness key of ``member`` on ``session``."""
    fields = (
        member.role,
        member.name,
        str(member.pid or 0),
        str(member.parent_pid or 0),
        member.host,
        member.config,
        member.endpoint,
    )
    return "/".join((PRESENCE_PREFIX, str(session.domain_id), session.zid, *(_chunk(f) for f in fields)))


def parse_presence(key: str) -> Member | None:
    """The member a presence key announces (None for anything else)."""
    parts = str(key).split("/")
    if len(parts) != 10 or parts[0] != PRESENCE_PREFIX or parts[3] not in ROLES:
        return None
    try:
        pid, parent = int(parts[5]), int(parts[6])
    except ValueError:
        return None
    return Member(
        role=parts[3],
        zid=parts[2],
        name=_unchunk(parts[4]),
        pid=pid or None,
        parent_pid=parent or None,
        host=_unchunk(parts[7]),
        config=_unchunk(parts[8]),
        endpoint=_unchunk(parts[9]),
    )


def declare_presence(
    session: Session, role: str, *, name: str = "", config: str = "", endpoint: str = ""
) -> Any:
    """Announce this process as the cell's ``role`` (``agent`` or ``driver``).

    The announcement lives as long as the session (the session holds it and withdraws it when it
    closes); ``close()`` on the returned object withdraws it earlier.
    """
    member = Member(
        role=role,
        zid=session.zid,
        name=name or role,
        pid=os.getpid(),
        parent_pid=os.getppid(),
        host=socket.gethostname(),
        config=config,
        endpoint=endpoint or ",".join(session.endpoints or session.listen),
    )
    return _Presence(session, session.zenoh.liveliness().declare_token(presence_key(session, member)))


class _Presence:
    """A declared presence token, held by its session (a dropped zenoh token is withdrawn at once)."""

    def __init__(self, session: Session, token: Any) -> None:
        self._session = session
        self._token: Any = token
        session._register_closer(self)

    def close(self) -> None:
        token, self._token = self._token, None
        if token is not None:
            self._session._unregister_closer(self)
            token.undeclare()


def query_presences(session: Session, timeout: float = 1.0) -> list[Member]:
    """Every presence on the session's domain, asked of the network now."""
    replies = session.zenoh.liveliness().get(f"{PRESENCE_PREFIX}/{session.domain_id}/**", timeout=timeout)
    members = []
    for reply in replies:
        if reply.ok is not None:
            member = parse_presence(str(reply.ok.key_expr))
            if member is not None:
                members.append(member)
    return members
