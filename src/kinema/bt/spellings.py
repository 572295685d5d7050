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
old behavior wins over the rename. An old ID whose behavior has no counterpart Kinema can run is refused
at load with its reason and how MoveIt Pro writes it today (``refused``), instead of "unknown node".

MoveIt Pro's removed ``LoadObjectiveParameters`` (a YAML file beside the objective, one section per
behavior name, handed to the behaviors that take ``parameters="{parameters}"``) is read by
:func:`apply_objective_parameters`, before the renames: each section's values become the ports of the
behaviors it names (today's way of giving them), the loader becomes ``AlwaysSuccess``, and a note lists
what was set and what has no port.
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
        refused: the old ID has no counterpart Kinema can run: loading refuses it with this reason (and
            what to write today), naming the file and line.
    """

    old_id: str = ""
    ports: Mapping[str, str] = field(default_factory=dict)
    dropped: Mapping[str, str] = field(default_factory=dict)
    accepted_values: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    current_id: str = ""
    subtree: bool = False
    origin: str = "MoveIt Pro"
    refused: str = ""

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
    if old_id and spelling.refused:
        raise BTRuntimeError(
            f"{old_id} is {origin}'s removed behavior and Kinema cannot run it: {spelling.refused}",
            location=SourceLocation(filename, line),
        )
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


OBJECTIVE_PARAMETERS_LOADER = "LoadObjectiveParameters"
_PARAMETERS_PORT = "parameters"


def _element_id(element: etree._Element) -> str | None:
    return element.get("ID") if element.tag in _EXPLICIT_TAGS else str(element.tag)


def _blackboard_key(value: str) -> str:
    text = value.strip()
    return text[1:-1].strip() if text.startswith("{") and text.endswith("}") else text


def _attribute_text(value: object) -> str | None:
    """A YAML value as a port's text, as MoveIt Pro's parameter reader took it; None for a mapping."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list | tuple):
        parts = [_attribute_text(v) for v in value]
        return None if any(p is None for p in parts) else ";".join(p for p in parts if p is not None)
    if isinstance(value, dict):
        return None
    return str(value)


def _load_parameters(element: etree._Element, filename: str) -> tuple[str, dict[str, dict[str, object]]]:
    """The file a LoadObjectiveParameters node names (beside the objective) and its sections."""
    from pathlib import Path

    import yaml

    line = element.sourceline or 0
    name = (element.get("config_file_name") or "").strip()
    where = SourceLocation(filename, line)
    if not name or "{" in name:
        raise BTRuntimeError(
            f"{OBJECTIVE_PARAMETERS_LOADER} needs config_file_name as a file name written in the objective "
            f"(got {name!r}): Kinema reads the file when the objective loads",
            location=where,
        )
    folder = Path(filename).resolve().parent
    path = folder / name
    if not path.is_file():
        raise BTRuntimeError(
            f"{OBJECTIVE_PARAMETERS_LOADER}: no file {name!r} beside the objective (looked in {folder})",
            location=where,
        )
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as error:
        raise BTRuntimeError(
            f"{OBJECTIVE_PARAMETERS_LOADER}: {path} cannot be read as YAML: {error}", location=where
        ) from None
    if not isinstance(data, dict) or not all(isinstance(v, dict) for v in data.values()):
        raise BTRuntimeError(
            f"{OBJECTIVE_PARAMETERS_LOADER}: {path} must map behavior names to their parameters "
            "(DetectAprilTags: {tag_size: 0.05, ...})",
            location=where,
        )
    return name, {str(k): dict(v) for k, v in data.items()}


def apply_objective_parameters(
    root: etree._Element,
    filename: str,
    registered: Mapping[str, object],
    spellings: Mapping[str, list[FormerSpelling]],
    problems: list[BTRuntimeError] | None = None,
) -> list[SpellingNote]:
    """Read MoveIt Pro's ``LoadObjectiveParameters`` as the ports it gave (see the module docstring).

    A node with ``parameters="{key}"`` after a loader writing ``{key}`` (its ``parameters`` port, default
    ``{parameters}``) takes the section named like the node's ``name`` (else its ID): each value becomes
    the port of that name (or the port a former spelling renames it to) unless the node sets the port
    itself; a value with no such port is left out and named in the note.

    With ``problems`` (a validator reading the whole file), such a file is added to it instead and read as
    giving nothing, so that the file's other problems are reported too.

    Raises:
        BTRuntimeError: the file is not named literally, is not beside the objective, or is not a mapping
            of behavior names to parameters (naming the file and line); not with ``problems``.
    """
    if OBJECTIVE_PARAMETERS_LOADER in registered:
        return []  # a plugin provides the old behavior itself
    notes: list[SpellingNote] = []
    for tree in root.iterchildren("BehaviorTree"):
        loaded: dict[str, dict[str, dict[str, object]]] = {}
        unread: set[str] = set()
        for element in tree.iterdescendants(etree.Element):
            behavior = _element_id(element)
            location = SourceLocation(filename, element.sourceline or 0)
            if behavior == OBJECTIVE_PARAMETERS_LOADER:
                try:
                    name, sections = _load_parameters(element, filename)
                except BTRuntimeError as error:
                    if problems is None:
                        raise
                    problems.append(error)
                    name, sections = element.get("config_file_name") or "", {}
                    unread.add(_blackboard_key(element.get(_PARAMETERS_PORT) or "{parameters}"))
                key = _blackboard_key(element.get(_PARAMETERS_PORT) or "{parameters}")
                loaded[key] = sections
                label = element.get("name")
                element.attrib.clear()
                if label:
                    element.set("name", label)
                if element.tag in _EXPLICIT_TAGS:
                    element.set("ID", "AlwaysSuccess")
                else:
                    element.tag = "AlwaysSuccess"
                message = (
                    f"{OBJECTIVE_PARAMETERS_LOADER} is MoveIt Pro's removed way of giving behaviors "
                    f"their settings from a file; Kinema reads {name} when the objective loads and gives "
                    f"its values as the ports of the behaviors that take {{{key}}}; write them as those "
                    "ports instead"
                )
                notes.append(SpellingNote(location, message))
                continue
            value = element.get(_PARAMETERS_PORT)
            if value is None or behavior is None or _blackboard_key(value) not in loaded:
                continue
            if _blackboard_key(value) in unread:
                del element.attrib[_PARAMETERS_PORT]  # the file's problem is reported once, at the loader
                continue
            sections = loaded[_blackboard_key(value)]
            section = sections.get(element.get("name") or "") or sections.get(behavior) or {}
            manifest = registered.get(behavior)
            ports = set(getattr(manifest, "ports", {}) or {})
            renamed = {
                old: new for spelling in spellings.get(behavior, []) for old, new in spelling.ports.items()
            }
            given, ignored = [], []
            for parameter, setting in section.items():
                text = _attribute_text(setting)
                port = renamed.get(parameter, parameter)
                if text is None or port not in ports:
                    ignored.append(parameter)
                    continue
                if element.get(parameter) is None and element.get(port) is None:
                    element.set(parameter, text)
                    given.append(f"{port}={text}")
            del element.attrib[_PARAMETERS_PORT]
            message = f"{behavior}'s parameters come from the objective's parameter file: " + (
                ", ".join(given) or "none for it"
            )
            if ignored:
                message += f"; it has no port for {', '.join(ignored)}, which Kinema leaves out"
            notes.append(SpellingNote(location, message + "; write them as its ports instead"))
    return notes


__all__ = [
    "OBJECTIVE_PARAMETERS_LOADER",
    "FormerSpelling",
    "SpellingNote",
    "apply_objective_parameters",
    "rewrite_former_spellings",
]
