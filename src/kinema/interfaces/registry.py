"""The type registry: ROS IDL text (``.msg``/``.srv``/``.action``) → a rosbags Typestore, CDR and hashes.

Type names are ROS 2 style: ``pkg/msg/Name``, ``pkg/srv/Name``, ``pkg/action/Name``. A service
``pkg/srv/Name`` registers the messages ``pkg/srv/Name_Request`` and ``pkg/srv/Name_Response``; an
action ``pkg/action/Name`` registers ``_Goal``, ``_Result``, ``_Feedback`` and the wire messages rcl
builds around them (``_SendGoal_Request``, ``_SendGoal_Response``, ``_GetResult_Request``,
``_GetResult_Response``, ``_FeedbackMessage``). RIHS01 hashes of services and actions are computed over
the same synthetic wrapper types rosidl generates, so they match what a ROS 2 node puts on the wire.
"""

from __future__ import annotations

import struct
import threading
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.base import Nodetype
from rosbags.typesys.store import Typestore

from kinema.errors import TransportError, did_you_mean
from kinema.interfaces.typehash import rihs01

_UUID = "unique_identifier_msgs/msg/UUID"
_TIME = "builtin_interfaces/msg/Time"
_CLOCK = "rosgraph_msgs/msg/Clock"
# CDR little endian (XCDR1) encapsulation, and a Time's two fields after it.
_CDR_LE = b"\x00\x01\x00\x00"
_STAMP = struct.Struct("<iI")
_SERVICE_EVENT_INFO = "service_msgs/msg/ServiceEventInfo"
_KINDS = ("msg", "srv", "action")


def dds_type_name(type_name: str) -> str:
    """Return the DDS-mangled name rmw_zenoh uses in keys: ``pkg/srv/Name`` → ``pkg::srv::dds_::Name_``."""
    package, kind, name = split_type_name(type_name)
    return f"{package}::{kind}::dds_::{name}_"


def split_type_name(type_name: str) -> tuple[str, str, str]:
    """Split ``pkg/kind/Name`` (or ``pkg/Name``, taken as a message) into its three parts."""
    parts = type_name.strip().strip("/").split("/")
    if len(parts) == 2:
        parts = [parts[0], "msg", parts[1]]
    if len(parts) != 3 or not all(parts):
        raise TransportError(
            f"bad interface type name {type_name!r}: expected pkg/msg/Name, pkg/srv/Name or pkg/action/Name"
        )
    return parts[0], parts[1], parts[2]


@dataclass(frozen=True)
class ServiceType:
    """A service interface: its request/response message types, wire name and hash."""

    name: str
    request: str
    response: str
    dds_name: str
    type_hash: str


@dataclass(frozen=True)
class ActionType:
    """An action interface and the services/topics rcl builds it from (``<action>/_action/...``)."""

    name: str
    goal: str
    result: str
    feedback: str
    send_goal: ServiceType
    get_result: ServiceType
    cancel_goal: ServiceType
    feedback_message: str
    feedback_message_hash: str
    status: str
    status_hash: str


def _split_sections(text: str, count: int, path: str) -> list[str]:
    sections: list[list[str]] = [[]]
    for line in text.splitlines():
        if line.strip() == "---":
            sections.append([])
        else:
            sections[-1].append(line)
    if len(sections) != count:
        raise TransportError(f"{path}: expected {count} sections separated by '---', found {len(sections)}")
    return ["\n".join(lines) + "\n" for lines in sections]


def _rename(desc: Any, renames: dict[str, str]) -> Any:
    kind, rest = desc
    if kind == Nodetype.NAME:
        return (kind, renames.get(rest, rest))
    if kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):
        return (kind, (_rename(rest[0], renames), rest[1]))
    return desc


def _parse_struct(text: str, package: str, name: str, path: str) -> tuple[list[Any], list[Any]]:
    """Parse one message body; unqualified type names resolve to ``package/msg/*`` as in rosidl."""
    # Parsing under a msg name makes rosbags resolve bare references (``BehaviorParameter``) to the
    # package's msg namespace, which is the rule for .srv and .action files too.
    try:
        typesdict = get_types_from_msg(text, f"{package}/msg/{name}")
    except Exception as error:
        raise TransportError(f"{path}: cannot parse interface definition: {error}") from error
    ((_, (constants, fields)),) = typesdict.items()
    return constants, fields


@dataclass
class _Parsed:
    """Message definitions parsed from interface files, before registration."""

    pending: dict[str, tuple[list[Any], list[Any]]]
    services: list[tuple[str, str]]
    actions: list[tuple[str, str]]
    origins: dict[str, str] = field(default_factory=dict)

    def packages_used(self) -> set[str]:
        """Packages the parsed definitions refer to (actions also need action_msgs' CancelGoal)."""
        used: set[str] = set()

        def visit(desc: Any) -> None:
            kind, rest = desc
            if kind == Nodetype.NAME:
                used.add(rest.split("/", 1)[0])
            elif kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):
                visit(rest[0])

        for _, fields in self.pending.values():
            for _, desc in fields:
                visit(desc)
        if self.actions:
            used.add("action_msgs")
        return used


def _parse_files(files: Iterable[Path]) -> _Parsed:
    pending: dict[str, tuple[list[Any], list[Any]]] = {}
    services: list[tuple[str, str]] = []
    actions: list[tuple[str, str]] = []
    origins: dict[str, str] = {}
    for path in files:
        package, kind, name = path.parent.parent.name, path.parent.name, path.stem
        text = path.read_text(encoding="utf-8")
        before = set(pending)
        if kind == "msg":
            pending[f"{package}/msg/{name}"] = _parse_struct(text, package, name, str(path))
        elif kind == "srv":
            request, response = _split_sections(text, 2, str(path))
            pending[f"{package}/srv/{name}_Request"] = _parse_struct(
                request, package, f"{name}_Request", str(path)
            )
            pending[f"{package}/srv/{name}_Response"] = _parse_struct(
                response, package, f"{name}_Response", str(path)
            )
            services.append((package, name))
        else:
            goal, result, feedback = _split_sections(text, 3, str(path))
            base = f"{package}/action/{name}"
            pending[f"{base}_Goal"] = _parse_struct(goal, package, f"{name}_Goal", str(path))
            pending[f"{base}_Result"] = _parse_struct(result, package, f"{name}_Result", str(path))
            pending[f"{base}_Feedback"] = _parse_struct(feedback, package, f"{name}_Feedback", str(path))
            pending[f"{base}_SendGoal_Request"] = (
                [],
                [("goal_id", (Nodetype.NAME, _UUID)), ("goal", (Nodetype.NAME, f"{base}_Goal"))],
            )
            pending[f"{base}_SendGoal_Response"] = (
                [],
                [("accepted", (Nodetype.BASE, ("bool", 0))), ("stamp", (Nodetype.NAME, _TIME))],
            )
            pending[f"{base}_GetResult_Request"] = ([], [("goal_id", (Nodetype.NAME, _UUID))])
            pending[f"{base}_GetResult_Response"] = (
                [],
                [("status", (Nodetype.BASE, ("int8", 0))), ("result", (Nodetype.NAME, f"{base}_Result"))],
            )
            pending[f"{base}_FeedbackMessage"] = (
                [],
                [("goal_id", (Nodetype.NAME, _UUID)), ("feedback", (Nodetype.NAME, f"{base}_Feedback"))],
            )
            actions.append((package, name))
        origins.update(dict.fromkeys(set(pending) - before, str(path)))
    # A bare reference inside a .srv/.action (``GripperCommand command``) was resolved to pkg/msg/*;
    # the parts of the service or action itself live under pkg/srv/* and pkg/action/*.
    renames = {
        f"{p}/msg/{n}{suffix}": f"{p}/action/{n}{suffix}"
        for p, n in actions
        for suffix in ("_Goal", "_Result", "_Feedback")
    }
    renames.update(
        {
            f"{p}/msg/{n}{suffix}": f"{p}/srv/{n}{suffix}"
            for p, n in services
            for suffix in ("_Request", "_Response")
        }
    )
    renamed = {
        name: (constants, [(field, _rename(desc, renames)) for field, desc in fields])
        for name, (constants, fields) in pending.items()
    }
    return _Parsed(renamed, services, actions, origins)


class TypeRegistry:
    """All interface types Kinema knows, registered in a rosbags Typestore.

    Packages added with :meth:`add_directory` are parsed and registered the first time one of their
    types (or a type that refers to them) is looked up, so a process pays only for what it uses.
    Thread-safe; packages may be added while nodes run.
    """

    def __init__(self) -> None:
        self.typestore: Typestore = get_typestore(Stores.ROS2_JAZZY)
        self._lock = threading.RLock()
        self._services: dict[str, ServiceType] = {}
        self._actions: dict[str, ActionType] = {}
        # Synthetic wrappers used only for hashing (service and action description structs).
        self._hash_only: dict[str, tuple[list[Any], list[Any]]] = {}
        self._hashes: dict[str, str] = {}
        # package -> interface files not parsed yet
        self._unloaded: dict[str, list[Path]] = {}

    # -- loading ---------------------------------------------------------------------------------

    def add_directory(self, root: Path) -> None:
        """Make every ``<pkg>/{msg,srv,action}/*.{msg,srv,action}`` below ``root`` available.

        Files are parsed when a type of their package is first needed; :meth:`load_all` forces it.
        """
        files = sorted(
            p for p in root.glob("*/*/*") if p.parent.name in _KINDS and p.suffix[1:] == p.parent.name
        )
        with self._lock:
            for path in files:
                self._unloaded.setdefault(path.parent.parent.name, []).append(path)

    def add_files(self, files: Iterable[Path]) -> None:
        """Parse and register interface files now (package = the folder above ``msg``/``srv``/``action``)."""
        with self._lock:
            parsed = _parse_files(files)
            for package in parsed.packages_used():
                self._ensure_package(package)
            self._register(parsed)

    def load_all(self) -> None:
        """Parse and register every package added so far."""
        with self._lock:
            for package in list(self._unloaded):
                self._ensure_package(package)

    def packages(self) -> list[str]:
        """Interface packages Kinema added (loaded or not), without the standard ones of the store."""
        with self._lock:
            added = set(self._unloaded) | {n.split("/", 1)[0] for n in (*self._services, *self._actions)}
        return sorted(added)

    def _ensure_package(self, package: str) -> None:
        """Load ``package`` and the not-yet-loaded packages it refers to, in one registration."""
        if package not in self._unloaded:
            return
        with self._lock:
            todo, batch = [package], []
            while todo:
                name = todo.pop()
                files = self._unloaded.pop(name, None)
                if files is None:
                    continue
                parsed = _parse_files(files)
                batch.append(parsed)
                todo.extend(parsed.packages_used())
            merged = _Parsed({}, [], [])
            for parsed in batch:
                merged.pending.update(parsed.pending)
                merged.services.extend(parsed.services)
                merged.actions.extend(parsed.actions)
                merged.origins.update(parsed.origins)
            self._register(merged)

    def _ensure_for(self, type_name: str) -> None:
        if self._unloaded:
            self._ensure_package(type_name.strip("/").split("/", 1)[0])

    def _register(self, parsed: _Parsed) -> None:
        with self._lock:
            for name, (_, fields) in parsed.pending.items():
                known = self.typestore.fielddefs.get(name)
                if known is not None and [(f.lower(), d) for f, d in known[1]] != [
                    (f.lower(), d) for f, d in fields
                ]:
                    raise TransportError(
                        f"{parsed.origins.get(name, name)}: {name} is already defined with other fields "
                        f"({', '.join(f for f, _ in known[1])}); a type name can have only one definition"
                    )
            fresh = {
                name: defs for name, defs in parsed.pending.items() if name not in self.typestore.fielddefs
            }
            self._check_references(fresh, parsed.origins)
            if fresh:
                try:
                    self.typestore.register(fresh)  # type: ignore[arg-type]
                except Exception as error:  # rosbags raises TypesysError for a conflicting redefinition
                    raise TransportError(
                        f"cannot register interfaces {', '.join(sorted(fresh))}: {error}"
                    ) from error
            # CancelGoal (in action_msgs) must be known before any action refers to it.
            for package, name in sorted(parsed.services, key=lambda item: item[0] != "action_msgs"):
                self._add_service(f"{package}/srv/{name}")
            for package, name in parsed.actions:
                self._add_action(f"{package}/action/{name}")

    def _check_references(
        self, typesdict: dict[str, tuple[list[Any], list[Any]]], origins: dict[str, str]
    ) -> None:
        known = set(self.typestore.fielddefs) | set(typesdict)

        def refs(desc: Any) -> Iterable[str]:
            kind, rest = desc
            if kind == Nodetype.NAME:
                yield rest
            elif kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):
                yield from refs(rest[0])

        for owner, (_, fields) in typesdict.items():
            for field_name, desc in fields:
                for ref in refs(desc):
                    if ref not in known:
                        raise TransportError(
                            f"{origins.get(owner, owner)}: field {field_name!r} of {owner} uses unknown type "
                            f"{ref!r} ({did_you_mean(ref, known)})"
                        )

    def _service_wrapper(self, base: str) -> str:
        """Define the hash-only ``base`` service struct and its ``_Event`` message; return ``base``."""
        request, response, event = f"{base}_Request", f"{base}_Response", f"{base}_Event"
        self._hash_only[event] = (
            [],
            [
                ("info", (Nodetype.NAME, _SERVICE_EVENT_INFO)),
                ("request", (Nodetype.SEQUENCE, ((Nodetype.NAME, request), 1))),
                ("response", (Nodetype.SEQUENCE, ((Nodetype.NAME, response), 1))),
            ],
        )
        self._hash_only[base] = (
            [],
            [
                ("request_message", (Nodetype.NAME, request)),
                ("response_message", (Nodetype.NAME, response)),
                ("event_message", (Nodetype.NAME, event)),
            ],
        )
        return base

    def _service_type(self, base: str, wire_name: str) -> ServiceType:
        self._service_wrapper(base)
        return ServiceType(
            name=wire_name,
            request=f"{base}_Request",
            response=f"{base}_Response",
            dds_name=dds_type_name(base),
            type_hash=self.type_hash(base),
        )

    def _add_service(self, name: str) -> None:
        self._services[name] = self._service_type(name, name)

    def _add_action(self, name: str) -> None:
        send_goal = self._service_type(f"{name}_SendGoal", f"{name}_SendGoal")
        get_result = self._service_type(f"{name}_GetResult", f"{name}_GetResult")
        self._hash_only[name] = (
            [],
            [
                ("goal", (Nodetype.NAME, f"{name}_Goal")),
                ("result", (Nodetype.NAME, f"{name}_Result")),
                ("feedback", (Nodetype.NAME, f"{name}_Feedback")),
                ("send_goal_service", (Nodetype.NAME, f"{name}_SendGoal")),
                ("get_result_service", (Nodetype.NAME, f"{name}_GetResult")),
                ("feedback_message", (Nodetype.NAME, f"{name}_FeedbackMessage")),
            ],
        )
        status = "action_msgs/msg/GoalStatusArray"
        self._actions[name] = ActionType(
            name=name,
            goal=f"{name}_Goal",
            result=f"{name}_Result",
            feedback=f"{name}_Feedback",
            send_goal=send_goal,
            get_result=get_result,
            cancel_goal=self.service("action_msgs/srv/CancelGoal"),
            feedback_message=f"{name}_FeedbackMessage",
            feedback_message_hash=self.type_hash(f"{name}_FeedbackMessage"),
            status=status,
            status_hash=self.type_hash(status),
        )

    # -- lookups ---------------------------------------------------------------------------------

    def type_hash(self, type_name: str) -> str:
        """RIHS01 hash of a message, or of a service/action (their wrapper description)."""
        self._ensure_for(type_name)
        with self._lock:
            cached = self._hashes.get(type_name)
            if cached is None:
                defs = {**self.typestore.fielddefs, **self._hash_only}
                if type_name not in defs:
                    raise TransportError(
                        f"unknown interface type {type_name!r} ({did_you_mean(type_name, self.names())})"
                    )
                cached = self._hashes[type_name] = rihs01(type_name, defs)  # type: ignore[arg-type]
            return cached

    def names(self, kind: str | None = None) -> list[str]:
        """Names of the known interfaces, optionally only one kind (``msg``, ``srv``, ``action``)."""
        self.load_all()
        with self._lock:
            messages = [n for n in self.typestore.fielddefs if "/msg/" in n]
            by_kind = {"msg": messages, "srv": list(self._services), "action": list(self._actions)}
        if kind is None:
            return sorted(by_kind["msg"] + by_kind["srv"] + by_kind["action"])
        return sorted(by_kind[kind])

    def message_type(self, type_name: str) -> str:
        """Normalise and check a message type name (``pkg/Name`` → ``pkg/msg/Name``)."""
        package, kind, name = split_type_name(type_name)
        full = f"{package}/{kind}/{name}"
        self._ensure_for(full)
        if full not in self.typestore.fielddefs:
            raise TransportError(
                f"unknown message type {type_name!r} ({did_you_mean(full, self.names('msg'))})"
            )
        return full

    def message_class(self, type_name: str) -> type:
        """The rosbags dataclass of a message type."""
        return self.typestore.types[self.message_type(type_name)]  # type: ignore[no-any-return]

    def service(self, type_name: str) -> ServiceType:
        """Look up a service type (``pkg/srv/Name``)."""
        package, kind, name = split_type_name(type_name)
        full = f"{package}/{kind}/{name}"
        self._ensure_for(full)
        with self._lock:
            found = self._services.get(full)
        if found is None:
            raise TransportError(
                f"unknown service type {type_name!r} ({did_you_mean(full, self.names('srv'))})"
            )
        return found

    def action(self, type_name: str) -> ActionType:
        """Look up an action type (``pkg/action/Name``)."""
        package, kind, name = split_type_name(type_name)
        full = f"{package}/{kind}/{name}"
        self._ensure_for(full)
        with self._lock:
            found = self._actions.get(full)
        if found is None:
            raise TransportError(
                f"unknown action type {type_name!r} ({did_you_mean(full, self.names('action'))})"
            )
        return found

    def fields(self, type_name: str) -> list[tuple[str, Any]]:
        """Field definitions of a message type: ``[(name, rosbags field descriptor)]``."""
        return list(self.typestore.fielddefs[self.message_type(type_name)][1])

    def constants(self, type_name: str) -> list[tuple[str, str, Any]]:
        """Constants declared by a message type: ``[(name, base type, value)]``."""
        return list(self.typestore.fielddefs[self.message_type(type_name)][0])

    # -- CDR ---------------------------------------------------------------------------------------

    def serialize(self, message: object, type_name: str) -> bytes:
        """CDR (little endian, with the 4-byte encapsulation header) of ``message``."""
        self._ensure_for(type_name)
        try:
            return bytes(self.typestore.serialize_cdr(message, type_name, little_endian=True))
        except Exception as error:
            raise TransportError(
                f"cannot serialise {type(message).__name__} as {type_name}: {error}"
            ) from error

    def deserialize(self, data: bytes | memoryview, type_name: str) -> Any:
        """Decode CDR bytes of ``type_name`` into its rosbags dataclass."""
        self._ensure_for(type_name)
        if type_name == _CLOCK and len(data) == 12 and data[:4] == _CDR_LE:
            # /clock arrives at 100 Hz of sim time, often many times real time: read its two integers
            # directly (the same dataclasses the generic deserializer makes; other layouts go there).
            types = self.typestore.types
            sec, nanosec = _STAMP.unpack_from(data, 4)
            return types[_CLOCK](clock=types[_TIME](sec=sec, nanosec=nanosec))
        try:
            return self.typestore.deserialize_cdr(data, type_name)
        except Exception as error:
            raise TransportError(f"cannot decode {len(data)} bytes as {type_name}: {error}") from error
