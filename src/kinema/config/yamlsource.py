"""Reading YAML files so that every key can be traced back to ``file:line``.

Config and waypoint files are small, but their errors must point at the exact line. PyYAML's composer
(the C one when libyaml is present) builds a node tree that carries line marks; the document is
constructed from that tree by the safe constructor and, in the same pass, a table from key path to line
is recorded. Files are read as bytes first so that a non-UTF-8 or a far too large file gets a clear
message instead of a decoder traceback.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from kinema.errors import ConfigError, KinemaError, SourceLocation

_BaseLoader: type[yaml.SafeLoader] = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # type: ignore[assignment]


class AngleLoader(_BaseLoader):  # type: ignore[valid-type,misc]
    """PyYAML's safe loader plus MoveIt Pro's angle tags: ``!degrees 30`` is 30° in radians, ``!radians 0.5``
    is 0.5 (MoveIt Pro's joint_limits.yaml and waypoint files write limits so). A subclass, so PyYAML's
    own SafeLoader stays as it is for everyone else."""


def _angle(scale: float) -> Callable[[yaml.SafeLoader, yaml.Node], float]:
    def construct(loader: yaml.SafeLoader, node: yaml.Node) -> float:
        text = loader.construct_scalar(node)  # type: ignore[arg-type]
        try:
            return float(text) * scale
        except (TypeError, ValueError):
            raise yaml.constructor.ConstructorError(
                None, None, f"{node.tag} needs a number, got {text!r}", node.start_mark
            ) from None

    return construct


AngleLoader.add_constructor("!degrees", _angle(math.pi / 180.0))
AngleLoader.add_constructor("!radians", _angle(1.0))
_Loader = AngleLoader

#: Default size limit of a YAML file; config files are a few kB, waypoint files a few hundred kB.
MAX_YAML_BYTES = 16 * 1024 * 1024

KeyPath = tuple[Hashable, ...]


@dataclass
class YamlDocument:
    """A parsed YAML file: its data and the line of every mapping key and list item.

    Attributes:
        path: the file the document was read from (or a display name).
        data: the constructed Python value (dicts, lists, scalars).
        lines: 1-based line of each key path, e.g. ``("hardware", "robot_description", "urdf")``;
            list items are keyed by their index.
    """

    path: Path
    data: Any
    _lines: dict[KeyPath, int] | None = field(default_factory=dict, repr=False)
    _text: str | None = field(default=None, repr=False)

    @property
    def lines(self) -> dict[KeyPath, int]:
        """The line table (computed on first use for documents parsed with ``track_lines=False``)."""
        if self._lines is None:
            self._lines = {}
            if self._text is not None:
                _compose_lines(self._text, self, strict=False)
        return self._lines

    def line(self, key_path: Sequence[Hashable]) -> int:
        """Return the line of ``key_path``, or of its longest known prefix (0 when nothing is known)."""
        path = tuple(key_path)
        while path:
            found = self.lines.get(path)
            if found is not None:
                return found
            path = path[:-1]
        return self.lines.get((), 0)

    def location(self, key_path: Sequence[Hashable] = ()) -> SourceLocation:
        """Return ``file:line`` of ``key_path`` for error messages."""
        return SourceLocation(str(self.path), self.line(key_path))


def read_text_file(path: Path, *, max_bytes: int, error: type[KinemaError] = ConfigError) -> str:
    """Read a UTF-8 text file, refusing unreadable, too large and non-UTF-8 files with a clear error."""
    where = SourceLocation(str(path))
    try:
        with open(path, "rb") as handle:
            size = os.fstat(handle.fileno()).st_size
            # read one byte more than allowed: files whose size stat does not tell (pipes) are caught too
            data = b"" if size > max_bytes else handle.read(max_bytes + 1)
    except FileNotFoundError:
        raise error("the file does not exist", location=where) from None
    except IsADirectoryError:
        raise error("this is a folder, a file is expected", location=where) from None
    except OSError as exc:
        raise error(f"cannot read the file: {exc.strerror}", location=where) from None
    if size > max_bytes or len(data) > max_bytes:
        raise error(
            f"the file is {_megabytes(max(size, len(data)))}, "
            f"larger than the limit of {_megabytes(max_bytes)}",
            location=where,
        )
    return decode_utf8(data, str(path), error=error)


def decode_utf8(data: bytes, filename: str, *, error: type[KinemaError] = ConfigError) -> str:
    """Decode ``data`` as UTF-8 (a BOM is allowed); a bad byte is reported with its line."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise error(
            f"the file is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start})",
            location=SourceLocation(filename, line),
        ) from None


def _megabytes(size: int) -> str:
    return f"{size / (1024 * 1024):.1f} MB"


def load_yaml_file(
    path: str | Path, *, max_bytes: int = MAX_YAML_BYTES, track_lines: bool = True
) -> YamlDocument:
    """Read and parse one YAML file.

    With ``track_lines=False`` the file is parsed faster and the line table is computed only when an
    error message asks for a line (a key written twice is then not detected).

    Raises:
        ConfigError: the file is missing, unreadable, too large, not UTF-8, not valid YAML, or has a
            key twice in one mapping; the message carries ``file:line``.
    """
    path = Path(path)
    return parse_yaml(read_text_file(path, max_bytes=max_bytes), path, track_lines=track_lines)


def parse_yaml(text: str, path: str | Path = "<string>", *, track_lines: bool = True) -> YamlDocument:
    """Parse YAML text into a :class:`YamlDocument` (see :func:`load_yaml_file` for the errors)."""
    document = YamlDocument(path=Path(path), data=None)
    if track_lines:
        _compose_lines(text, document, strict=True)
        return document
    document._lines, document._text = None, text
    try:
        document.data = yaml.load(text, Loader=_Loader)
    except (yaml.YAMLError, RecursionError) as exc:
        raise _yaml_error(exc, document.path) from None
    return document


def _compose_lines(text: str, document: YamlDocument, *, strict: bool) -> None:
    """Parse ``text`` into ``document.data`` and fill its line table; ``strict`` rejects repeated keys."""
    loader = _Loader(text)
    lines = document._lines if document._lines is not None else {}
    document._lines = lines
    try:
        node = loader.get_single_node()
        if node is not None:
            data = loader.construct_document(node)
            if strict or document.data is None:
                document.data = data
            lines[()] = node.start_mark.line + 1
            _record_lines(node, data, lines, document.path, loader.construct_object, strict)
    except (yaml.YAMLError, RecursionError) as exc:
        raise _yaml_error(exc, document.path) from None
    finally:
        loader.dispose()


def _yaml_error(exc: BaseException, path: Path) -> ConfigError:
    if isinstance(exc, RecursionError):
        return ConfigError("invalid YAML: nested too deeply", location=SourceLocation(str(path)))
    if isinstance(exc, yaml.MarkedYAMLError):
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else 0
        problem = " ".join(part for part in (exc.context, exc.problem) if part)
        if exc.context_mark is not None and mark is not None and exc.context_mark.line != mark.line:
            problem += f" (the construct began on line {exc.context_mark.line + 1})"
        return ConfigError(f"invalid YAML: {problem}", location=SourceLocation(str(path), line))
    return ConfigError(f"invalid YAML: {exc}", location=SourceLocation(str(path)))


def _record_lines(
    node: yaml.Node,
    data: Any,
    lines: dict[KeyPath, int],
    path_name: Path,
    construct_key: Callable[[yaml.Node], Any],
    strict: bool,
) -> None:
    """Walk the node tree beside the constructed value, recording the line of every key and item."""
    # An explicit loop over a stack: deeply nested (hostile) files must not hit the recursion limit.
    stack: list[tuple[yaml.Node, Any, KeyPath]] = [(node, data, ())]
    seen: set[int] = set()
    while stack:
        current, current_value, path = stack.pop()
        if id(current) in seen:  # an alias: its lines were recorded where the anchor is
            continue
        seen.add(id(current))
        if isinstance(current, yaml.MappingNode) and isinstance(current_value, dict):
            first_line: dict[Hashable, int] = {}
            for key_node, value_node in current.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue
                key = construct_key(key_node)
                line = key_node.start_mark.line + 1
                if key in first_line:
                    if not strict:
                        continue
                    raise ConfigError(
                        f"the key {key!r} appears twice in one mapping (first on line {first_line[key]})",
                        location=SourceLocation(str(path_name), line),
                    )
                first_line[key] = line
                child_path = (*path, key)
                lines[child_path] = line
                if key in current_value:
                    stack.append((value_node, current_value[key], child_path))
        elif isinstance(current, yaml.SequenceNode) and isinstance(current_value, list):
            for index, (item_node, item_value) in enumerate(zip(current.value, current_value, strict=False)):
                child_path = (*path, index)
                lines[child_path] = item_node.start_mark.line + 1
                stack.append((item_node, item_value, child_path))
