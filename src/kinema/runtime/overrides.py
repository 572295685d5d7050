"""Parameter overrides: values for an objective's blackboard, applied all-or-nothing before the first tick.

MoveIt Pro's semantics: once the tree is built, each override finds the type of the port that reads
its name, its text is parsed as YAML into that type, and it is written into the root blackboard, or into
the blackboards of the subtrees named by ``behavior_namespaces``. Any failure (no port reads that name,
a value of the wrong type, an unknown namespace) rejects the whole request before the tree ticks:
overrides never apply partially.

An objective's own ports (``<TreeNodesModel><SubTree ID>``) carry defaults, which MoveIt Pro's request
says overrides replace ("Default values of named parameters in the predefined objective will be
overridden"). BT.CPP applies them only where the objective is a ``<SubTree>`` of another; an objective
run on its own gets them here, as if it were that SubTree with no attributes: each literal default
(neither empty nor a ``{key}``) is parsed into the type of the port that reads it and written into the
root blackboard, unless an override sets the name. A default no port reads, or one that does not parse
into the port's type, is left out, and the tree reads the key as it would without it (whether MoveIt Pro
itself seeds them is not public; its UI and ``kinema objective show`` present them as the values used).
"""

from __future__ import annotations

import enum
import logging
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from kinema.errors import ObjectiveError, did_you_mean

if TYPE_CHECKING:
    from kinema.bt import Blackboard, Tree
    from kinema.bt.xmlparser import SubtreeModel

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ParameterOverride:
    """One override.

    Attributes:
        name: the blackboard key (the name of the port's ``{key}``) to set.
        value: YAML text (``from_yaml=True``, as ``BehaviorParameter.string_value`` carries it) or an
            already typed value (a double, int, bool, pose or joint state field).
        behavior_namespaces: subtrees (by ID, instance name or path) whose blackboard receives the value;
            empty means the root blackboard.
        from_yaml: whether ``value`` is text to parse as YAML.
    """

    name: str
    value: Any
    behavior_namespaces: tuple[str, ...] = ()
    from_yaml: bool = True

    @classmethod
    def parse(cls, assignment: str) -> ParameterOverride:
        """Parse ``NAME=VALUE`` (the CLI's ``--param``); the value stays YAML text.

        Raises:
            ObjectiveError: no ``=`` or an empty name.
        """
        name, sep, value = assignment.partition("=")
        if not sep or not name.strip():
            raise ObjectiveError(f"bad parameter {assignment!r}: expected NAME=VALUE (VALUE in YAML)")
        return cls(name.strip(), value)


def model_defaults(model: SubtreeModel | None) -> list[ParameterOverride]:
    """The literal defaults of an objective's own ports (see the module's docstring), as overrides."""
    from kinema.bt.ports import blackboard_pointer

    if model is None:
        return []
    # A {key} default wires the port to a key of the caller's: at the root there is nothing to seed.
    return [
        ParameterOverride(name, text)
        for name, port in model.ports.items()
        if (text := port.default_str) and text.strip() and blackboard_pointer(text, name) is None
    ]


def apply_overrides(
    tree: Tree,
    overrides: Sequence[ParameterOverride],
    *,
    objective_name: str = "",
    defaults: Sequence[ParameterOverride] = (),
    parameters: Sequence[str] = (),
) -> None:
    """Convert every override and write them all into ``tree``'s blackboards, or none of them.

    ``defaults`` (from :func:`model_defaults`) are written first into the root blackboard, each where a
    port reads its name and no override (for the root) sets it; one that does not convert is skipped.
    ``parameters`` are the ports the objective declares: an override of a name no port reads suggests
    them (rather than every key of the blackboard, the outputs its behaviors write included).

    Raises:
        ObjectiveError: naming the override, the objective and what would have been accepted.
    """
    writes: list[tuple[Blackboard, str, Any]] = []
    overridden = {o.name for o in overrides if not o.behavior_namespaces}
    root = tree.root_blackboard
    for default in defaults:
        entry = root.get_entry(default.name)
        if default.name in overridden or entry is None or entry.value is not None:
            continue
        try:
            writes.append((root, default.name, _convert(root, "", default, objective_name)))
        except ObjectiveError as error:
            log.debug("default left out: %s", error)
    for override in overrides:
        for blackboard, scope in _target_blackboards(tree, override, objective_name):
            value = _convert(blackboard, scope, override, objective_name, () if scope else parameters)
            writes.append((blackboard, override.name, value))
    for blackboard, key, value in writes:
        blackboard.set(key, value)


def _target_blackboards(
    tree: Tree, override: ParameterOverride, objective_name: str
) -> list[tuple[Blackboard, str]]:
    if not override.behavior_namespaces:
        return [(tree.root_blackboard, "")]
    scopes = _subtree_scopes(tree)
    targets: list[tuple[Blackboard, str]] = []
    for namespace in override.behavior_namespaces:
        matches = [(bb, path) for path, names, bb in scopes if namespace in names]
        if not matches:
            choices = sorted({name for _, names, _ in scopes for name in names if name})
            raise ObjectiveError(
                f"parameter override {override.name!r} of objective {objective_name!r}: no subtree is named "
                f"{namespace!r}; {did_you_mean(namespace, choices)}"
            )
        targets.extend(matches)
    return targets


def _subtree_scopes(tree: Tree) -> list[tuple[str, set[str], Blackboard]]:
    """``(path, names it answers to, blackboard)`` for every subtree instance of ``tree``."""
    scopes = []
    for subtree in tree.subtrees:
        path = getattr(subtree, "instance_name", "") or ""
        names = {path, path.rsplit("/", 1)[-1], getattr(subtree, "tree_id", "") or ""}
        scopes.append((path, {n for n in names if n}, subtree.blackboard))
    return scopes


def _convert(
    blackboard: Blackboard,
    scope: str,
    override: ParameterOverride,
    objective_name: str,
    parameters: Sequence[str] = (),
) -> Any:
    where = f"parameter override {override.name!r} of objective {objective_name!r}"
    entry = blackboard.get_entry(override.name)
    if entry is None:
        keys = list(parameters) or _visible_keys(blackboard)
        place = f"subtree {scope!r}" if scope else "the objective"
        raise ObjectiveError(
            f"{where}: no port of {place} reads the blackboard key {override.name!r}; "
            f"{did_you_mean(override.name, keys)}"
        )
    port_type = entry.type
    try:
        if override.from_yaml:
            return parse_yaml_value(str(override.value), port_type)
        return coerce_value(override.value, port_type)
    except (ValueError, TypeError) as error:
        raise ObjectiveError(f"{where}: {error}") from None


def _visible_keys(blackboard: Blackboard) -> list[str]:
    keys: set[str] = set()
    scope: Blackboard | None = blackboard
    while scope is not None:
        keys.update(scope.keys())
        scope = scope.parent
    return sorted(keys)


def _type_label(port_type: Any) -> str:
    from kinema.bt.conversions import type_name

    return type_name(port_type)


def parse_yaml_value(text: str, port_type: Any) -> Any:
    """Parse ``text`` as YAML into a value of ``port_type`` (None = any type).

    Strings are taken as written unless quoted in YAML, so ``Look at Table`` and ``007`` stay strings
    for a string port. Lists also accept BT.CPP's ``1;2;3`` form.

    Raises:
        ValueError: the text is not YAML, or not a value of that type.
    """
    import yaml

    from kinema.bt.conversions import AnyValue, ConversionError, Unsigned, convert_from_string, has_converter
    from kinema.nesting import load_yaml

    try:
        parsed = load_yaml(text, "the value") if text.strip() else text
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at column {mark.column + 1}" if mark is not None else ""
        raise ValueError(f"{text!r} is not valid YAML{where}") from None
    if port_type is None or port_type is AnyValue:
        return parsed
    if port_type is str:
        return parsed if isinstance(parsed, str) else text
    if isinstance(parsed, str) and port_type in (int, Unsigned, float):
        # YAML left it a string (1e3, 0x10, or 0.5x): the whole of it must be the number. BT.CPP's own
        # conversion reads a leading number and ignores the rest, which suits XML attributes written by
        # hand, not a value a program or a form sends.
        try:
            number: float | int = float(parsed) if port_type is float else _whole_int(parsed)
        except ValueError:
            raise ValueError(f"{text!r} is not a valid {_type_label(port_type)}") from None
        return coerce_value(number, port_type, text=text)
    if isinstance(parsed, str) and has_converter(port_type) and not _is_class_type(port_type):
        try:
            return convert_from_string(port_type, parsed)
        except ConversionError as error:
            raise ValueError(f"{text!r} is not a valid {_type_label(port_type)} ({error})") from None
    return coerce_value(parsed, port_type, text=text)


def _whole_int(text: str) -> int:
    """``text`` as an int, decimal (``08`` too) or with a base prefix (``0x10``); ValueError otherwise."""
    try:
        return int(text.strip(), 10)
    except ValueError:
        return int(text.strip(), 0)


def _is_class_type(port_type: Any) -> bool:
    from kinema.bt.conversions import Unsigned

    return (
        isinstance(port_type, type)
        and port_type not in (int, Unsigned, float, str, bool, list)
        and not issubclass(port_type, enum.Enum)
    )


def coerce_value(value: Any, port_type: Any, *, text: str | None = None) -> Any:
    """Turn an already parsed value into ``port_type`` without losing information.

    Raises:
        ValueError: the value does not fit the type (a float for an int port, a word for a bool, ...).
    """
    from kinema.bt.conversions import AnyValue, Unsigned, list_item_type

    shown = text if text is not None else repr(value)
    label = _type_label(port_type)
    if port_type is None or port_type is AnyValue:
        return value
    if port_type is bool:
        if isinstance(value, bool):
            return value
        raise ValueError(f"{shown} is not a bool (port type {label}; use true or false)")
    if port_type is int or port_type is Unsigned:
        number = None
        if isinstance(value, int) and not isinstance(value, bool):
            number = value
        elif isinstance(value, float) and value.is_integer():
            number = int(value)
        if number is None:
            raise ValueError(f"{shown} is not an int (port type {label})")
        if port_type is Unsigned and not 0 <= number <= 2**32 - 1:
            raise ValueError(f"{shown} is not in 0 .. 4294967295 (port type {label})")
        return number
    if port_type is float:
        if isinstance(value, int | float) and not isinstance(value, bool):
            return float(value)
        raise ValueError(f"{shown} is not a number (port type {label})")
    if port_type is str:
        if isinstance(value, str):
            return value
        raise ValueError(f"{shown} is not a string (port type {label})")
    item = list_item_type(port_type)
    if item is not None or port_type is list:
        if not isinstance(value, list | tuple):
            raise ValueError(f"{shown} is not a list (port type {label})")
        return [coerce_value(v, item) for v in value] if item is not None else list(value)
    if isinstance(port_type, type) and issubclass(port_type, enum.Enum):
        if isinstance(value, port_type):
            return value
        if isinstance(value, str) and value in port_type.__members__:
            return port_type.__members__[value]
        try:
            return port_type(value)
        except ValueError:
            valid = ", ".join(port_type.__members__)
            raise ValueError(f"{shown} is not a {label} (valid: {valid})") from None
    if isinstance(port_type, type) and isinstance(value, port_type):
        return value
    if isinstance(value, dict):
        return _from_mapping(port_type, value, shown)
    from_string = getattr(port_type, "from_string", None)
    if isinstance(value, str) and callable(from_string):
        return from_string(value)
    raise ValueError(f"{shown} cannot be read as {label}")


def _from_mapping(port_type: Any, value: dict[str, Any], shown: str) -> Any:
    """Build a ROS message value from a YAML mapping (``{header: {frame_id: world}, pose: ...}``)."""
    type_name = getattr(port_type, "__msgtype__", None)
    if not isinstance(type_name, str):
        raise ValueError(f"{shown} cannot be read as {_type_label(port_type)}")
    from kinema.errors import TransportError
    from kinema.transport.messages import from_dict

    try:
        return from_dict(type_name, value)
    except TransportError as error:
        raise ValueError(f"{shown} is not a valid {type_name}: {error}") from None
