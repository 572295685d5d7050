"""The semantic robot description (SRDF): planning groups, end effectors, named states, disabled collisions.

Only the parts Kinema uses are read; unknown elements are ignored, as MoveIt does. Groups keep their raw
definition (chains, joints, links, subgroups); :class:`~kinema.motion.robot_model.RobotModel` resolves
them into joint lists against the URDF.

An element without an attribute it needs is skipped with a note (``file:line: ...``), as MoveIt's SRDF
reader skips it with an error in its log: a file MoveIt loads, Kinema loads. One exception: a
``<group_state>`` without ``group`` keeps its joint values under the group ``""`` (pinocchio reads such
states, and robot descriptions written for it, such as example-robot-data's, leave the group out), so its
values still give a waypoint.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from kinema.errors import MotionError, SourceLocation


@dataclass(frozen=True)
class GroupDefinition:
    """A ``<group>`` as written: ``chains`` are (base_link, tip_link) pairs."""

    name: str
    chains: tuple[tuple[str, str], ...] = ()
    joints: tuple[str, ...] = ()
    links: tuple[str, ...] = ()
    subgroups: tuple[str, ...] = ()


@dataclass(frozen=True)
class EndEffector:
    """An ``<end_effector>``: the ``group`` attached to ``parent_link`` of ``parent_group``."""

    name: str
    group: str
    parent_link: str
    parent_group: str = ""


@dataclass(frozen=True)
class SemanticDescription:
    """Everything Kinema reads from an SRDF file."""

    robot_name: str = ""
    groups: dict[str, GroupDefinition] = field(default_factory=dict)
    group_states: dict[tuple[str, str], dict[str, float]] = field(default_factory=dict)
    end_effectors: tuple[EndEffector, ...] = ()
    passive_joints: tuple[str, ...] = ()
    disabled_collisions: frozenset[frozenset[str]] = frozenset()
    #: ``file:line: what was skipped and why`` for each element without an attribute it needs.
    notes: tuple[str, ...] = ()

    def gripper_positions(self, joint: str) -> tuple[float | None, float | None]:
        """``(open, closed)`` of ``joint`` from the group states named ``open`` and ``close`` (or
        ``closed``) that set it, as MoveIt Pro's gripper objectives move it; None for one not given."""
        by_name = {
            name.lower(): values for (_group, name), values in self.group_states.items() if joint in values
        }
        opened, closed = by_name.get("open"), by_name.get("close", by_name.get("closed"))
        return (
            None if opened is None else float(opened[joint]),
            None if closed is None else float(closed[joint]),
        )

    def collision_disabled(self, link1: str, link2: str) -> bool:
        """True when the SRDF says the pair ``link1``/``link2`` is never checked."""
        return frozenset((link1, link2)) in self.disabled_collisions


class _Reader:
    """Reads the attributes elements need, noting each element skipped for lack of one."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.notes: list[str] = []

    def where(self, element: etree._Element) -> str:
        return f"{self.path}:{element.sourceline or 0}"

    def values(self, element: etree._Element, *attributes: str) -> tuple[str, ...] | None:
        """The attributes' values, or None (and a note) when one is missing or empty."""
        values = tuple(element.get(attribute, "").strip() for attribute in attributes)
        missing = [attribute for attribute, value in zip(attributes, values, strict=True) if not value]
        if not missing:
            return values
        needs = " and ".join(repr(attribute) for attribute in missing)
        self.notes.append(
            f"{self.where(element)}: <{element.tag}> has no {needs} attribute; skipped, as MoveIt skips it"
        )
        return None

    def value(self, element: etree._Element, attribute: str) -> str | None:
        found = self.values(element, attribute)
        return found[0] if found is not None else None


def parse_srdf(path: str | Path) -> SemanticDescription:
    """Read an SRDF file (elements missing an attribute they need are skipped: see the module's doc).

    Raises:
        MotionError: the file is missing, is not XML, or a joint value of a group state is not a number.
    """
    path = Path(path)
    try:
        root = etree.parse(str(path)).getroot()
    except OSError as exc:
        raise MotionError(f"cannot read SRDF {path}: {exc}") from exc
    except etree.XMLSyntaxError as exc:
        raise MotionError(
            f"SRDF is not valid XML: {exc}", location=SourceLocation(str(path), exc.lineno or 0)
        ) from exc
    read = _Reader(path)
    groups: dict[str, GroupDefinition] = {}
    # Only the top-level <group> elements define groups: a <group name="arm"/> inside another group is a
    # reference to "arm" (a composite group such as Franka's arm_and_hand), not a new, empty "arm".
    for g in root.findall("group"):
        name = read.value(g, "name")
        if name is None:
            continue
        chains = (read.values(c, "base_link", "tip_link") for c in g.findall("chain"))
        groups[name] = GroupDefinition(
            name=name,
            chains=tuple((ends[0], ends[1]) for ends in chains if ends is not None),
            joints=_present(read.value(j, "name") for j in g.findall("joint")),
            links=_present(read.value(link, "name") for link in g.findall("link")),
            subgroups=_present(read.value(s, "name") for s in g.findall("group")),
        )
    states: dict[tuple[str, str], dict[str, float]] = {}
    for s in root.findall("group_state"):
        name = read.value(s, "name")
        if name is None:
            continue
        group = s.get("group", "").strip()
        if not group:
            read.notes.append(
                f"{read.where(s)}: <group_state name={name!r}> names no group; its joint values are kept "
                "(MoveIt skips such a state)"
            )
        values: dict[str, float] = {}
        for j in s.findall("joint"):
            joint = read.values(j, "name", "value")
            if joint is None:
                continue
            try:
                values[joint[0]] = float(joint[1].split()[0])
            except ValueError:
                raise MotionError(
                    f"group state {name!r}: joint {joint[0]!r} has the value {joint[1]!r}, not a number",
                    location=SourceLocation(str(path), j.sourceline or 0),
                ) from None
        states[(group, name)] = values
    effectors = []
    for e in root.iter("end_effector"):
        fields = read.values(e, "name", "group", "parent_link")
        if fields is not None:
            name, group, parent_link = fields
            effectors.append(EndEffector(name, group, parent_link, e.get("parent_group", "").strip()))
    pairs = (read.values(d, "link1", "link2") for d in root.iter("disable_collisions"))
    disabled = frozenset(frozenset(pair) for pair in pairs if pair is not None)
    passive = _present(read.value(p, "name") for p in root.iter("passive_joint"))
    return SemanticDescription(
        robot_name=root.get("name", ""),
        groups=groups,
        group_states=states,
        end_effectors=tuple(effectors),
        passive_joints=passive,
        disabled_collisions=disabled,
        notes=tuple(read.notes),
    )


def _present(values: Iterable[str | None]) -> tuple[str, ...]:
    return tuple(value for value in values if value is not None)
