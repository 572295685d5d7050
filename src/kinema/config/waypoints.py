"""Named joint-space waypoints in MoveIt Pro's waypoints YAML.

The file is a YAML list; each item has the fields of ``moveit_studio_agent_msgs/Waypoint``::

    - name: Look at Table
      description: ''
      favorite: false
      joint_group_names: [gripper, linear_actuator, manipulator]
      joint_state: {header: {...}, name: [...], position: [...], velocity: [], effort: []}
      multi_dof_joint_state: {header: {...}, joint_names: [], transforms: [], twist: [], wrench: []}

Fields Kinema does not model (a header's frame, multi-DOF states, anything new) are kept as read.

Every change (save, rename, erase) takes the file's lock (a sidecar ``.lock`` file, see
:mod:`kinema.config.file_lock`), reads the current file, changes it and replaces it atomically, so
concurrent writers in threads or processes never lose each other's waypoints and readers never see a
half-written file.

A change is a round trip through ruamel.yaml: the file's comments, the order of its waypoints and keys,
its quoting and indentation stay as they were, and only the values that changed are written anew (an
unchanged number keeps its digits). A new waypoint is appended with its keys sorted, as MoveIt Pro
writes them.
"""

from __future__ import annotations

import copy
import functools
import io
from collections.abc import Iterator, MutableMapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from kinema.config.atomic_write import atomic_write_text, remove_temporaries_of
from kinema.config.file_lock import locked
from kinema.config.yamlsource import YamlDocument, load_yaml_file
from kinema.errors import ConfigError, SourceLocation, did_you_mean

MAX_WAYPOINTS_BYTES = 64 * 1024 * 1024


def _empty_header() -> dict[str, Any]:
    return {"frame_id": "", "stamp": {"nanosec": 0, "sec": 0}}


@dataclass
class Waypoint:
    """A named robot configuration.

    Attributes:
        name: unique within its file.
        joint_names: the joints of ``positions``, same order.
        positions: joint positions in rad (revolute) or m (prismatic).
        joint_group_names: planning groups the waypoint was saved for.
        description: free text.
        favorite: shown first in UIs.
        velocities / efforts: usually empty.
        raw: the item as read from the file; fields not modeled here are written back from it.
    """

    name: str
    joint_names: list[str]
    positions: list[float]
    joint_group_names: list[str] = field(default_factory=list)
    description: str = ""
    favorite: bool = False
    velocities: list[float] = field(default_factory=list)
    efforts: list[float] = field(default_factory=list)
    raw: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)

    def joint_positions(self) -> dict[str, float]:
        """Joint name -> position."""
        return dict(zip(self.joint_names, self.positions, strict=True))

    def to_dict(self) -> dict[str, Any]:
        """The item as MoveIt Pro writes it (fields not modeled here kept from :attr:`raw`)."""
        item = copy.deepcopy(self.raw)
        found = item.get("joint_state")
        joint_state: dict[str, Any] = found if isinstance(found, dict) else {}
        joint_state.setdefault("header", _empty_header())
        joint_state.update(
            name=list(self.joint_names),
            position=[float(p) for p in self.positions],
            velocity=[float(v) for v in self.velocities],
            effort=[float(e) for e in self.efforts],
        )
        item.update(
            name=self.name,
            description=self.description,
            favorite=self.favorite,
            joint_group_names=list(self.joint_group_names),
            joint_state=joint_state,
        )
        item.setdefault(
            "multi_dof_joint_state",
            {"header": _empty_header(), "joint_names": [], "transforms": [], "twist": [], "wrench": []},
        )
        return item

    @classmethod
    def from_dict(cls, item: Any, document: YamlDocument, index: int) -> Waypoint:
        """Build a waypoint from one list item of a waypoints file.

        Raises:
            ConfigError: a field is missing or has the wrong type (with file:line).
        """
        where = (index,)
        if not isinstance(item, dict):
            raise ConfigError(
                "each waypoint must be a mapping with name:, joint_state:, ...",
                location=document.location(where),
            )
        name = item.get("name")
        if not isinstance(name, str) or not name:
            raise ConfigError("a waypoint needs a non-empty string name:", location=document.location(where))
        joint_state = item.get("joint_state")
        if not isinstance(joint_state, dict):
            raise ConfigError(
                f"waypoint {name!r} needs a joint_state: mapping with name: and position: lists",
                location=document.location((*where, "joint_state")),
            )
        joint_names = _list(joint_state.get("name"), str, document, (*where, "joint_state", "name"), name)
        positions = _list(
            joint_state.get("position"), (int, float), document, (*where, "joint_state", "position"), name
        )
        if len(joint_names) != len(positions):
            raise ConfigError(
                f"waypoint {name!r} has {len(joint_names)} joint names but {len(positions)} positions",
                location=document.location((*where, "joint_state", "position")),
            )
        groups = _list(item.get("joint_group_names"), str, document, (*where, "joint_group_names"), name)
        return cls(
            name=name,
            joint_names=joint_names,
            positions=[float(p) for p in positions],
            joint_group_names=groups,
            description=str(item.get("description") or ""),
            favorite=bool(item.get("favorite", False)),
            velocities=[
                float(v) for v in _list(joint_state.get("velocity"), (int, float), document, where, name)
            ],
            efforts=[float(e) for e in _list(joint_state.get("effort"), (int, float), document, where, name)],
            raw=item,
        )


def _list(
    value: Any, kind: type | tuple[type, ...], document: YamlDocument, where: tuple[Any, ...], name: str
) -> list[Any]:
    if value is None:
        return []
    if not isinstance(value, list) or not all(isinstance(v, kind) and not isinstance(v, bool) for v in value):
        wanted = "strings" if kind is str else "numbers"
        raise ConfigError(
            f"waypoint {name!r}: {where[-1]} must be a list of {wanted}", location=document.location(where)
        )
    return value


class WaypointStore:
    """The waypoints of one file, as the file is at every call, and changed under the file's lock.

    A call reads the file again only when it changed (its inode, size or modification time differ from
    the last read): an edit made by hand is seen at the next call, and a run that looks up a waypoint
    per motion does not parse the YAML each time.

    Args:
        path: the file changes are written to.
        seed_from: the file to read while ``path`` does not exist yet (an inherited waypoints file, see
            :mod:`kinema.config.waypoint_location`); the first change copies its waypoints to ``path``.
        notice: why ``path`` is not the file the config names (for logs and UIs); empty otherwise.
    """

    def __init__(self, path: str | Path, *, seed_from: str | Path | None = None, notice: str = "") -> None:
        self.path = Path(path)
        self.seed_from = Path(seed_from) if seed_from is not None else None
        self.notice = notice
        # (path, inode, size, mtime_ns, ctime_ns) of the last read, and what it parsed to.
        self._parsed: tuple[tuple[Any, ...], list[Waypoint]] | None = None

    @property
    def read_path(self) -> Path:
        """The file waypoints are read from now."""
        if self.seed_from is not None and not self.path.exists():
            return self.seed_from
        return self.path

    def remove_stray_temporaries(self) -> list[Path]:
        """Delete temporary files a writer killed mid-save left beside the file; return them.

        Safe at any time: every writer holds the file's lock while its temporary file exists.
        """
        if not self.path.parent.is_dir():
            return []
        with locked(self.path):
            return remove_temporaries_of(self.path)

    def all(self) -> list[Waypoint]:
        """Every waypoint, in file order (an absent file has none).

        Raises:
            ConfigError: the file is not a valid waypoints file (with file:line).
        """
        return self._read()

    def names(self) -> list[str]:
        """The waypoint names, in file order."""
        return [waypoint.name for waypoint in self._read()]

    def get(self, name: str) -> Waypoint:
        """Return the waypoint ``name``.

        Raises:
            ConfigError: no such waypoint; the message lists the closest names.
        """
        waypoints = self._read()
        for waypoint in waypoints:
            if waypoint.name == name:
                return waypoint
        names = [w.name for w in waypoints]
        raise ConfigError(f"no waypoint named {name!r} in {self.read_path}; {did_you_mean(name, names)}")

    def save(self, waypoint: Waypoint) -> None:
        """Add ``waypoint``, or replace the one with the same name (keeping its place in the file)."""
        if not waypoint.name:
            raise ConfigError("a waypoint needs a non-empty name")
        if len(waypoint.joint_names) != len(waypoint.positions):
            raise ConfigError(
                f"waypoint {waypoint.name!r} has {len(waypoint.joint_names)} joint names but "
                f"{len(waypoint.positions)} positions"
            )
        with self._locked():
            waypoints = self._read()
            document, items = self._edit()
            names = [existing.name for existing in waypoints]
            if waypoint.name in names:
                _update(items[names.index(waypoint.name)], waypoint.to_dict())
            else:
                items.append(_new_node(waypoint.to_dict()))
            self._write(document)

    def rename(self, old: str, new: str) -> None:
        """Rename waypoint ``old`` to ``new``.

        Raises:
            ConfigError: ``old`` does not exist, or ``new`` is empty or already taken.
        """
        if not new:
            raise ConfigError("a waypoint needs a non-empty name")
        with self._locked():
            waypoints = self._read()
            names = [waypoint.name for waypoint in waypoints]
            if old not in names:
                where = self.read_path
                raise ConfigError(f"no waypoint named {old!r} in {where}; {did_you_mean(old, names)}")
            if new != old and new in names:
                raise ConfigError(f"a waypoint named {new!r} already exists in {self.path}")
            document, items = self._edit()
            items[names.index(old)]["name"] = new
            self._write(document)

    def erase(self, name: str) -> None:
        """Remove waypoint ``name``.

        Raises:
            ConfigError: no such waypoint.
        """
        with self._locked():
            waypoints = self._read()
            names = [waypoint.name for waypoint in waypoints]
            if name not in names:
                where = self.read_path
                raise ConfigError(f"no waypoint named {name!r} in {where}; {did_you_mean(name, names)}")
            document, items = self._edit()
            del items[names.index(name)]
            self._write(document)

    @contextmanager
    def _locked(self) -> Iterator[None]:
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise ConfigError(
                f"cannot create the folder of the waypoints file: {error.strerror}",
                location=SourceLocation(str(self.path.parent)),
            ) from None
        with locked(self.path):
            remove_temporaries_of(self.path)  # what a writer killed mid-save left behind
            yield

    def _read(self) -> list[Waypoint]:
        path = self.read_path
        try:
            stat = path.stat()
        except FileNotFoundError:
            return []
        except OSError:
            stat = None  # let the read below report it
        if stat is not None:
            key = (path, stat.st_ino, stat.st_size, stat.st_mtime_ns, stat.st_ctime_ns)
            parsed = self._parsed
            if parsed is not None and parsed[0] == key:
                return list(parsed[1])
        waypoints = self._parse(path)
        if stat is not None:
            self._parsed = (key, waypoints)
        return list(waypoints)

    def _parse(self, path: Path) -> list[Waypoint]:
        document = load_yaml_file(path, max_bytes=MAX_WAYPOINTS_BYTES, track_lines=False)
        if document.data is None:
            return []
        if not isinstance(document.data, list):
            raise ConfigError(
                "a waypoints file is a YAML list of waypoints (- name: ...)", location=document.location(())
            )
        waypoints: list[Waypoint] = []
        first_index: dict[str, int] = {}
        for index, item in enumerate(document.data):
            waypoint = Waypoint.from_dict(item, document, index)
            if waypoint.name in first_index:
                first, line = document.line((first_index[waypoint.name],)), document.line((index,))
                raise ConfigError(
                    f"two waypoints are named {waypoint.name!r} (lines {first} and {line})",
                    location=SourceLocation(str(self.path), line),
                )
            first_index[waypoint.name] = index
            waypoints.append(waypoint)
        return waypoints

    def _edit(self) -> tuple[_RoundTrip, Any]:
        """The file being changed, as a round trip, and its list of waypoints (called after :meth:`_read`
        found the file valid, under the lock)."""
        path = self.read_path
        text = path.read_text(encoding="utf-8") if path.exists() else ""
        return _RoundTrip.load(text)

    def _write(self, document: _RoundTrip) -> None:
        atomic_write_text(self.path, document.dump())


class _SourceFloat(float):
    """A float read from the file, which writes itself back with the file's own digits (ruamel.yaml 0.19
    rewrites ``-2.9355287074907658e-05`` as ``-2.9355287074907657e-05``)."""

    text: str

    def __new__(cls, value: float, text: str) -> _SourceFloat:
        number = super().__new__(cls, value)
        number.text = text
        return number


@functools.cache
def _yaml_classes() -> tuple[type, type]:
    """ruamel.yaml's round-trip constructor and representer, keeping floats' digits (subclasses, so other
    users of ruamel.yaml in the process are not affected)."""
    from ruamel.yaml.constructor import RoundTripConstructor
    from ruamel.yaml.representer import RoundTripRepresenter

    class Constructor(RoundTripConstructor):
        pass

    class Representer(RoundTripRepresenter):
        pass

    def construct_float(constructor: Any, node: Any) -> Any:
        value = constructor.construct_yaml_float(node)
        return _SourceFloat(float(value), str(node.value)) if node.style is None else value

    def represent_float(representer: Any, data: _SourceFloat) -> Any:
        return representer.represent_scalar("tag:yaml.org,2002:float", data.text)

    Constructor.add_constructor("tag:yaml.org,2002:float", construct_float)
    Representer.add_representer(_SourceFloat, represent_float)
    return Constructor, Representer


def _round_trip_yaml() -> Any:
    from ruamel.yaml import YAML

    yaml = YAML()
    yaml.Constructor, yaml.Representer = _yaml_classes()
    yaml.preserve_quotes = True
    yaml.width = 4096  # never fold a long line the file did not fold
    return yaml


class _RoundTrip:
    """A waypoints file loaded with ruamel.yaml's round-trip loader, dumped with its own indentation."""

    def __init__(self, items: Any, indent: int, block_seq_indent: int) -> None:
        self.items = items
        self.indent = indent
        self.block_seq_indent = block_seq_indent

    @classmethod
    def load(cls, text: str) -> tuple[_RoundTrip, Any]:
        from ruamel.yaml.comments import CommentedSeq
        from ruamel.yaml.util import load_yaml_guess_indent

        if text.strip():
            items, indent, block_seq_indent = load_yaml_guess_indent(text, yaml=_round_trip_yaml())
        else:
            items, indent, block_seq_indent = None, 2, 0
        if items is None:
            items = CommentedSeq()
        if isinstance(items, CommentedSeq) and not items:
            items.fa.set_block_style()  # an empty file's `[]`: waypoints added to it are written as blocks
        document = cls(items, indent or 2, block_seq_indent or 0)
        return document, items

    def dump(self) -> str:
        yaml = _round_trip_yaml()
        yaml.indent(
            mapping=self.indent,
            sequence=self.indent + self.block_seq_indent,
            offset=self.block_seq_indent,
        )
        if not self.items:
            return "[]\n"
        buffer = io.StringIO()
        yaml.dump(self.items, buffer)
        return buffer.getvalue()


def _update(node: MutableMapping[str, Any], values: dict[str, Any]) -> None:
    """Write ``values`` into the round-trip ``node``, replacing only what differs (so the rest keeps its
    comments and formatting)."""
    for key, value in values.items():
        current = node.get(key)
        if isinstance(value, dict) and isinstance(current, MutableMapping):
            _update(current, value)
        elif isinstance(value, list) and isinstance(current, list) and current:
            if not _same_list(current, value):
                current[:] = [_new_node(v) for v in value]
        elif key not in node or not _same_scalar(current, value):
            node[key] = _new_node(value)


def _same_scalar(a: Any, b: Any) -> bool:
    return type(a) is type(b) and a == b if isinstance(a, bool) or isinstance(b, bool) else a == b


def _same_list(current: list[Any], value: list[Any]) -> bool:
    return len(current) == len(value) and all(
        _same_scalar(a, b) if not isinstance(b, dict | list) else a == b
        for a, b in zip(current, value, strict=True)
    )


def _new_node(value: Any) -> Any:
    """A round-trip node of plain data, mappings with their keys sorted (MoveIt Pro's layout)."""
    from ruamel.yaml.comments import CommentedMap, CommentedSeq

    if isinstance(value, dict):
        return CommentedMap((key, _new_node(value[key])) for key in sorted(value))
    if isinstance(value, list):
        return CommentedSeq(_new_node(v) for v in value)
    return value
