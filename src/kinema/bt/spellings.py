"""Former spellings: node IDs and port names that were renamed, read as today's with a note.

MoveIt Pro renamed behaviors and ports over its releases (``CreateStampedPose`` is ``CreatePoseStamped``
today, ``GetImage``'s ``timeout_sec`` is ``message_timeout_sec``) and its migration guides list each old
spelling with the current one. An objective written for an older release keeps loading here: when a
document is loaded, every node written the old way is rewritten in place to today's spelling, before the
document is verified, so the builder, the validator and every later reader see only current names. Each
rewrite leaves a :class:`SpellingNote` (``file:line``: the old spelling, the current one) that
``kinema build`` prints as a warning.

A port that has no current counterpart is either dropped with its reason, or, when only some of its
values mean nothing today (``keep_orientation="false"``), dropped for those values and refused with its
reason for the others: an objective never silently loses what it asked for.

An old ID that is registered as a node type of its own is left alone: a plugin that still provides the
old behavior wins over the rename.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from lxml import etree

from kinema.bt.errors import BTRuntimeError
from kinema.errors import SourceLocation

_EXPLICIT_TAGS = frozenset({"Action", "Condition", "Control", "Decorator"})


@dataclass(frozen=True)
class FormerSpelling:
    """An old way of writing a node that is read as today's.

    Attributes:
        old_id: the former node ID; ``""`` when only ports of today's ID were renamed.
        ports: former port name -> today's port name.
        dropped: former port name -> why it has no counterpart today (the node is loaded without it).
        accepted_values: for a dropped port, the only literal values it may be dropped with; any other
            value (a ``{pointer}`` included) is refused with the port's reason. Absent: any value.
        current_id: today's node ID; ``""`` for the behavior the spelling is declared on (the registry
            fills it in when it registers the behavior).
        subtree: ``current_id`` is a SubTree (the old behavior became an objective): the node is
            rewritten to ``<SubTree ID=current_id>`` with the same ports.
        origin: whose old spelling it is, for the note.
    """

    old_id: str = ""
    ports: Mapping[str, str] = field(default_factory=dict)
    dropped: Mapping[str, str] = field(default_factory=dict)
    accepted_values: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    current_id: str = ""
    subtree: bool = False
    origin: str = "MoveIt Pro"

    @property
    def spelled_id(self) -> str:
        """The ID the spelling is found under in XML: the old ID, else today's."""
        return self.old_id or self.current_id


@dataclass(frozen=True)
class SpellingNote:
    """One node read under today's spelling: where it is written and what was rewritten."""

    location: SourceLocation
    message: str

    def __str__(self) -> str:
        return f"{self.location}: {self.message}"


def rewrite_former_spellings(
    root: etree._Element,
    filename: str,
    spellings: Mapping[str, list[FormerSpelling]],
    registered: Mapping[str, object],
) -> list[SpellingNote]:
    """Rewrite, in place, every node of ``root``'s trees written in a former spelling; one note each.

    Args:
        root: a BT.CPP ``<root>`` document.
        filename: the document's file, for the notes.
        spellings: the spelled ID (old or current) -> its former spellings (see the factory).
        registered: the registered node IDs; an old ID registered as a node type is not rewritten.

    Raises:
        BTRuntimeError: a dropped port carries a value that is not one of its accepted values.
    """
    notes: list[SpellingNote] = []
    for tree in root.iterchildren("BehaviorTree"):
        for element in tree.iterdescendants(etree.Element):
            read: set[str] = set()
            # An old ID rewritten to today's may also carry today's ID's old port names: read again.
            while True:
                tag = element.tag
                spelled = element.get("ID") if tag in _EXPLICIT_TAGS else tag
                found = spellings.get(spelled) if tag != "SubTree" and spelled else None
                if not found or spelled in read:
                    break
                read.add(spelled)
                for spelling in found:
                    if spelling.old_id and spelling.old_id in registered:
                        continue
                    message = _rewrite(element, spelling, filename)
                    if message:
                        notes.append(SpellingNote(SourceLocation(filename, element.sourceline or 0), message))
    return notes


def _rewrite(element: etree._Element, spelling: FormerSpelling, filename: str) -> str:
    """Rewrite one element to today's spelling; the note's text ('' when nothing was old)."""
    old_id, current_id, origin = spelling.old_id, spelling.current_id, spelling.origin
    line = element.sourceline or 0
    renamed: list[tuple[str, str]] = []
    for old_port, new_port in spelling.ports.items():
        value = element.get(old_port)
        if value is None or element.get(new_port) is not None:
            # Both spellings given: left for the loader to refuse the old one as an unknown port.
            continue
        del element.attrib[old_port]
        element.set(new_port, value)
        renamed.append((old_port, new_port))
    ignored: list[tuple[str, str]] = []
    for old_port, reason in spelling.dropped.items():
        value = element.get(old_port)
        if value is None:
            continue
        accepted = spelling.accepted_values.get(old_port)
        if accepted is not None and value.strip() not in accepted:
            choices = ", ".join(repr(v) for v in accepted)
            raise BTRuntimeError(
                f"{old_id or current_id}'s port {old_port}={value!r} is {origin}'s old spelling and Kinema "
                f"cannot honour it: {reason}; give {choices} or leave the port out",
                location=SourceLocation(filename, line),
            )
        del element.attrib[old_port]
        ignored.append((old_port, reason))
    if old_id:
        if spelling.subtree:
            element.tag = "SubTree"
            element.set("ID", current_id)
        elif element.tag in _EXPLICIT_TAGS:
            element.set("ID", current_id)
        else:
            element.tag = current_id
        target = f"the SubTree '{current_id}'" if spelling.subtree else current_id
        message = f"{old_id} is {origin}'s old name of {target}"
        if renamed:
            message += " (" + ", ".join(f"its port {old} is {new}" for old, new in renamed) + ")"
        message += f"; read as {current_id}, write that instead"
    elif renamed:
        ports = ", ".join(f"{old} is {origin}'s old name of {new}" for old, new in renamed)
        message = f"{current_id}'s port {ports}; read so, write the current name instead"
    elif ignored:
        names = " and ".join(name for name, _ in ignored)
        plural = len(ignored) > 1
        message = (
            f"{current_id}'s port{'s' if plural else ''} {names} {'are' if plural else 'is'} {origin}'s old "
            "spelling with no counterpart today"
        )
    else:
        return ""
    if ignored:
        if len(ignored) == 1:
            message += f"; Kinema ignores {ignored[0][0]}: {ignored[0][1]}"
        else:
            message += "; Kinema ignores them (" + "; ".join(f"{name}: {why}" for name, why in ignored) + ")"
    return message


__all__ = ["FormerSpelling", "SpellingNote", "rewrite_former_spellings"]
