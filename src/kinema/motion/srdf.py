"""The semantic robot description (SRDF): planning groups, end effectors, named states, disabled collisions.

Only the parts Kinema uses are read; unknown elements are ignored, as MoveIt does. Groups keep their raw
definition (chains, joints, links, subgroups); :class:`~kinema.motion.robot_model.RobotModel` resolves
them into joint lists against the URDF.
"""

from __future__ import annotations

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

    def collision_disabled(self, link1: str, link2: str) -> bool:
        """True when the SRDF says the pair ``link1``/``link2`` is never checked."""
        return frozenset((link1, link2)) in self.disabled_collisions


def _required(element: etree._Element, attribute: str, path: Path) -> str:
    value = element.get(attribute)
    if not value:
        raise MotionError(
            f"<{element.tag}> needs a {attribute!r} attribute",
            location=SourceLocation(str(path), element.sourceline or 0),
        )
    return value


def parse_srdf(path: str | Path) -> SemanticDescription:
    """Read an SRDF file.

    Raises:
        MotionError: the file is missing, is not XML, or an element lacks a required attribute.
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
    groups: dict[str, GroupDefinition] = {}
    # Only the top-level <group> elements define groups: a <group name="arm"/> inside another group is a
    # reference to "arm" (a composite group such as Franka's arm_and_hand), not a new, empty "arm".
    for g in root.findall("group"):
        name = _required(g, "name", path)
        groups[name] = GroupDefinition(
            name=name,
            chains=tuple(
                (_required(c, "base_link", path), _required(c, "tip_link", path)) for c in g.findall("chain")
            ),
            joints=tuple(_required(j, "name", path) for j in g.findall("joint")),
            links=tuple(_required(link, "name", path) for link in g.findall("link")),
            subgroups=tuple(_required(s, "name", path) for s in g.findall("group")),
        )
    states: dict[tuple[str, str], dict[str, float]] = {}
    for s in root.findall("group_state"):
        key = (_required(s, "group", path), _required(s, "name", path))
        states[key] = {
            _required(j, "name", path): float(_required(j, "value", path)) for j in s.findall("joint")
        }
    effectors = tuple(
        EndEffector(
            name=_required(e, "name", path),
            group=_required(e, "group", path),
            parent_link=_required(e, "parent_link", path),
            parent_group=e.get("parent_group", ""),
        )
        for e in root.iter("end_effector")
    )
    disabled = frozenset(
        frozenset((_required(d, "link1", path), _required(d, "link2", path)))
        for d in root.iter("disable_collisions")
    )
    passive = tuple(_required(p, "name", path) for p in root.iter("passive_joint"))
    return SemanticDescription(
        robot_name=root.get("name", ""),
        groups=groups,
        group_states=states,
        end_effectors=effectors,
        passive_joints=passive,
        disabled_collisions=disabled,
    )
