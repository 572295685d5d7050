"""The robot model used for planning: joints, planning groups and limits from URDF + SRDF + joint_limits.yaml.

A configuration ``q`` is a float array of shape ``(n,)`` over :attr:`RobotModel.joint_names` (the *active*
joints: every revolute or prismatic joint that is not a mimic of another), in metres for prismatic and
radians for revolute joints. Mimic joints (the gripper's second finger, say) follow their leader and never
appear in ``q``; :meth:`RobotModel.pin_configuration` expands ``q`` into pinocchio's full vector.
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from lxml import etree

from kinema.errors import MotionError, SourceLocation, did_you_mean
from kinema.motion.joint_limits import JointLimits, LimitsFile, merge_limits, parse_joint_limits
from kinema.motion.srdf import GroupDefinition, SemanticDescription, parse_srdf

if TYPE_CHECKING:
    import pinocchio as pin

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Mimic:
    """``follower = multiplier * leader + offset`` (a URDF ``<mimic>``)."""

    leader: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class JointGroup:
    """A planning group: its active joints (in model order) and, for chains, the base and tip links."""

    name: str
    joint_names: tuple[str, ...]
    indices: tuple[int, ...]  # positions of joint_names in RobotModel.joint_names
    base_link: str | None = None
    tip_link: str | None = None


@dataclass(frozen=True)
class _UrdfJoint:
    name: str
    kind: str
    parent: str
    child: str
    mimic: Mimic | None


def _parse_urdf_joints(path: Path) -> dict[str, _UrdfJoint]:
    try:
        root = etree.parse(str(path)).getroot()
    except OSError as exc:
        raise MotionError(f"cannot read URDF {path}: {exc}") from exc
    except etree.XMLSyntaxError as exc:
        raise MotionError(
            f"URDF is not valid XML: {exc}", location=SourceLocation(str(path), exc.lineno or 0)
        ) from exc
    joints: dict[str, _UrdfJoint] = {}
    for j in root.findall("joint"):
        mimic_el = j.find("mimic")
        mimic = None
        if mimic_el is not None:
            mimic = Mimic(
                leader=mimic_el.get("joint", ""),
                multiplier=float(mimic_el.get("multiplier", "1")),
                offset=float(mimic_el.get("offset", "0")),
            )
        parent, child = j.find("parent"), j.find("child")
        joints[j.get("name", "")] = _UrdfJoint(
            name=j.get("name", ""),
            kind=j.get("type", ""),
            parent=parent.get("link", "") if parent is not None else "",
            child=child.get("link", "") if child is not None else "",
            mimic=mimic,
        )
    return joints


CONTINUOUS_RANGE = 2.0 * math.pi
"""A URDF ``continuous`` joint plans as a revolute joint within ±this (two turns), rad."""


def _has_continuous(joints: Mapping[str, _UrdfJoint]) -> bool:
    return any(joint.kind == "continuous" for joint in joints.values())


def _continuous_as_revolute(path: Path) -> str:
    """The URDF with each ``continuous`` joint made ``revolute`` within ±:data:`CONTINUOUS_RANGE` (its effort
    and velocity kept): pinocchio gives a continuous joint two coordinates (cos, sin), which planning,
    limits and trajectories here do not take; two turns either way cover what an arm's wrist is asked."""
    root = etree.parse(str(path)).getroot()
    for joint in root.findall("joint"):
        if joint.get("type") != "continuous":
            continue
        joint.set("type", "revolute")
        limit = joint.find("limit")
        if limit is None:
            limit = etree.SubElement(joint, "limit", effort="0", velocity="0")
        limit.set("lower", repr(-CONTINUOUS_RANGE))
        limit.set("upper", repr(CONTINUOUS_RANGE))
    return etree.tostring(root, encoding="unicode")


class RobotModel:
    """A kinematic robot model for planning, built with pinocchio from a URDF.

    Attributes:
        name: the robot's name (from the URDF).
        joint_names: the active joints, the coordinates of every configuration ``q`` (shape ``(n,)``).
        limits: position, velocity and acceleration limits per active joint.
        groups: planning groups from the SRDF, by name.
        semantic: the parsed SRDF (disabled collision pairs, end effectors, named states).
        pin_model: the pinocchio model (all joints, mimic followers included).
        urdf_path: where the URDF was read from.
    """

    def __init__(
        self,
        pin_model: pin.Model,
        urdf_path: Path,
        urdf_joints: dict[str, _UrdfJoint],
        semantic: SemanticDescription,
        limits_file: LimitsFile | None,
    ) -> None:
        self.pin_model = pin_model
        self.urdf_path = urdf_path
        self.package_dirs: list[str] = [str(urdf_path.parent)]
        self.name = pin_model.name
        self.semantic = semantic
        self._urdf_joints = urdf_joints
        self.mimics: dict[str, Mimic] = {n: j.mimic for n, j in urdf_joints.items() if j.mimic is not None}
        pin_names = [pin_model.names[i] for i in range(1, pin_model.njoints)]
        for name in pin_names:
            jid = pin_model.getJointId(name)
            if pin_model.nqs[jid] != 1 or pin_model.nvs[jid] != 1:
                raise MotionError(
                    f"joint {name!r} in {urdf_path} has {pin_model.nqs[jid]} coordinates; "
                    "only revolute, continuous (planned within two turns) and prismatic joints are supported"
                )
        for follower, mimic in self.mimics.items():
            if mimic.leader not in pin_names or mimic.leader in self.mimics:
                raise MotionError(
                    f"joint {follower!r} mimics {mimic.leader!r}, which is not an independent joint; "
                    f"{did_you_mean(mimic.leader, [n for n in pin_names if n not in self.mimics])}",
                    location=SourceLocation(str(urdf_path)),
                )
        self.joint_names: tuple[str, ...] = tuple(n for n in pin_names if n not in self.mimics)
        #: Every joint that moves: the active ones, then the mimic followers (what a joint state may name).
        followers = tuple(n for n in pin_names if n in self.mimics)
        self.moving_joint_names: tuple[str, ...] = (*self.joint_names, *followers)
        self._index = {n: i for i, n in enumerate(self.joint_names)}
        self._pin_q_index = {n: pin_model.idx_qs[pin_model.getJointId(n)] for n in pin_names}
        self._pin_v_index = {n: pin_model.idx_vs[pin_model.getJointId(n)] for n in pin_names}
        overrides = limits_file.joints if limits_file else {}
        self.default_velocity_scaling_factor = (
            limits_file.default_velocity_scaling_factor if limits_file else 1.0
        )
        self.default_acceleration_scaling_factor = (
            limits_file.default_acceleration_scaling_factor if limits_file else 1.0
        )
        self.limits: dict[str, JointLimits] = {}
        for name in pin_names:
            qi, vi = self._pin_q_index[name], self._pin_v_index[name]
            self.limits[name] = merge_limits(
                name,
                float(pin_model.lowerPositionLimit[qi]),
                float(pin_model.upperPositionLimit[qi]),
                float(pin_model.velocityLimit[vi]),
                overrides.get(name),
            )
        self.lower = np.array([self.limits[n].lower for n in self.joint_names])
        self.upper = np.array([self.limits[n].upper for n in self.joint_names])
        self.max_velocity = np.array([self.limits[n].max_velocity for n in self.joint_names])
        self.max_acceleration = np.array([self.limits[n].max_acceleration for n in self.joint_names])
        # Maps active joint velocities to pinocchio's full velocity vector (mimic followers included).
        self.mimic_map = np.zeros((pin_model.nv, len(self.joint_names)))
        for name in pin_names:
            follows = self.mimics.get(name)
            leader, factor = (follows.leader, follows.multiplier) if follows else (name, 1.0)
            self.mimic_map[self._pin_v_index[name], self._index[leader]] = factor
        self._mimic_offsets = np.zeros(pin_model.nq)
        for name, mimic in self.mimics.items():
            self._mimic_offsets[self._pin_q_index[name]] = mimic.offset
        self.groups: dict[str, JointGroup] = {
            name: self._resolve_group(name, semantic.groups, set()) for name in semantic.groups
        }
        self.link_names: tuple[str, ...] = tuple(
            f.name for f in pin_model.frames if f.type == _pin().FrameType.BODY
        )
        self._collision_geometry: pin.GeometryModel | None = None
        self._collision_geometry_lock = threading.Lock()

    def collision_geometry(self) -> pin.GeometryModel:
        """The robot's collision geometry (the URDF's ``<collision>`` shapes), read once: each
        :class:`~kinema.motion.collision.CollisionChecker` takes a copy, which shares the shapes (meshes
        loaded and their bounding-volume trees built once per model, not per checker and thread: a
        robot with 34 STL meshes took 1.5-2.7 s per checker).

        Raises:
            MotionError: pinocchio cannot read the geometry (a missing or unreadable mesh).
        """
        with self._collision_geometry_lock:
            if self._collision_geometry is None:
                pin = _pin()
                try:
                    self._collision_geometry = pin.buildGeomFromUrdf(
                        self.pin_model,
                        str(self.urdf_path),
                        pin.GeometryType.COLLISION,
                        package_dirs=list(self.package_dirs),
                    )
                except (RuntimeError, ValueError) as exc:
                    where = self.urdf_path
                    raise MotionError(f"cannot build collision geometry from {where}: {exc}") from exc
            return self._collision_geometry

    @classmethod
    def from_urdf(
        cls,
        urdf_path: str | Path,
        srdf_path: str | Path | None = None,
        joint_limits_path: str | Path | None = None,
        package_dirs: Iterable[str | Path] = (),
    ) -> RobotModel:
        """Build the model from a URDF, plus an optional SRDF (groups) and MoveIt joint_limits.yaml.

        Raises:
            MotionError: a file is missing or malformed, a group names an unknown joint or link.

        ``package_dirs`` are the folders holding the packages the URDF's ``package://`` meshes name
        (:func:`kinema.config.robot_description.package_index` gives a config's).
        """
        pin = _pin()
        urdf_path = Path(urdf_path)
        joints = _parse_urdf_joints(urdf_path)
        try:
            bounded = _continuous_as_revolute(urdf_path) if _has_continuous(joints) else None
            model = pin.buildModelFromXML(bounded) if bounded else pin.buildModelFromUrdf(str(urdf_path))
        except (RuntimeError, ValueError) as exc:
            raise MotionError(f"pinocchio cannot load URDF {urdf_path}: {exc}") from exc
        semantic = parse_srdf(srdf_path) if srdf_path is not None else SemanticDescription()
        for note in semantic.notes:
            log.warning("%s", note)
        limits = parse_joint_limits(joint_limits_path) if joint_limits_path is not None else None
        robot = cls(model, urdf_path, joints, semantic, limits)
        # Where package:// and relative mesh paths of the URDF are found (the collision model's meshes).
        robot.package_dirs = [str(urdf_path.parent), *(str(d) for d in package_dirs)]
        return robot

    # -- groups and names -------------------------------------------------------------------------

    def _resolve_group(self, name: str, defs: Mapping[str, GroupDefinition], seen: set[str]) -> JointGroup:
        if name in seen:
            raise MotionError(f"SRDF group {name!r} contains itself through its subgroups")
        d = defs[name]
        joints: list[str] = []
        base = tip = None
        child_to_joint = {j.child: j for j in self._urdf_joints.values()}
        for base_link, tip_link in d.chains:
            base, tip = base_link, tip_link
            chain: list[str] = []
            link = tip_link
            while link != base_link:
                parent_joint = child_to_joint.get(link)
                if parent_joint is None:
                    raise MotionError(
                        f"SRDF group {name!r}: no chain from {base_link!r} to {tip_link!r}; "
                        f"{did_you_mean(link, self._all_links())}"
                    )
                chain.append(parent_joint.name)
                link = parent_joint.parent
            joints.extend(reversed(chain))
        for joint in d.joints:
            if joint not in self._urdf_joints:
                raise MotionError(
                    f"SRDF group {name!r} names unknown joint {joint!r}; "
                    f"{did_you_mean(joint, self._urdf_joints)}"
                )
            joints.append(joint)
        for link in d.links:
            moving = child_to_joint.get(link)
            if link not in self._all_links():
                raise MotionError(
                    f"SRDF group {name!r} names unknown link {link!r}; "
                    f"{did_you_mean(link, self._all_links())}"
                )
            if moving is not None:
                joints.append(moving.name)
        for sub in d.subgroups:
            if sub not in defs:
                raise MotionError(
                    f"SRDF group {name!r} includes unknown group {sub!r}; {did_you_mean(sub, defs)}"
                )
            joints.extend(self._resolve_group(sub, defs, seen | {name}).joint_names)
        active = set(joints) & set(self.joint_names)
        ordered = tuple(n for n in self.joint_names if n in active)
        if tip is None:
            tip = next((e.parent_link for e in self.semantic.end_effectors if e.parent_group == name), None)
        return JointGroup(name, ordered, tuple(self._index[n] for n in ordered), base, tip)

    def _all_links(self) -> set[str]:
        links = {j.child for j in self._urdf_joints.values()} | {j.parent for j in self._urdf_joints.values()}
        return links

    def group(self, name: str) -> JointGroup:
        """Return planning group ``name``.

        Raises:
            MotionError: unknown group, with the valid group names.
        """
        try:
            return self.groups[name]
        except KeyError:
            raise MotionError(f"unknown planning group {name!r}; {did_you_mean(name, self.groups)}") from None

    def index(self, joint: str) -> int:
        """Position of active joint ``joint`` in a configuration vector.

        Raises:
            MotionError: unknown or mimic joint, with the valid names.
        """
        try:
            return self._index[joint]
        except KeyError:
            raise MotionError(f"unknown joint {joint!r}; {did_you_mean(joint, self.joint_names)}") from None

    def frame_id(self, frame: str) -> int:
        """pinocchio frame id of link or frame ``frame``.

        Raises:
            MotionError: unknown frame, with the valid link names.
        """
        if not self.pin_model.existFrame(frame):
            raise MotionError(f"unknown frame {frame!r}; {did_you_mean(frame, self.link_names)}")
        pin = _pin()
        # A fixed joint named like its child link (the Unitree Z1's gripperStator) makes two frames of
        # that name; the link's is the one meant (pinocchio refuses the name alone as ambiguous).
        if self.pin_model.existFrame(frame, pin.FrameType.BODY):
            return int(self.pin_model.getFrameId(frame, pin.FrameType.BODY))
        matches = [i for i, f in enumerate(self.pin_model.frames) if f.name == frame]
        return matches[0]

    # -- configurations ---------------------------------------------------------------------------

    def neutral(self) -> np.ndarray:
        """A configuration ``(n,)`` inside the limits: zero where allowed, else the nearest limit."""
        return np.clip(np.zeros(len(self.joint_names)), self.lower, self.upper)

    def configuration(
        self, positions: Mapping[str, float] | Iterable[float] | None = None, base: np.ndarray | None = None
    ) -> np.ndarray:
        """Build a configuration ``(n,)`` from positions by joint name (others from ``base``, else neutral).

        An array-like of length ``n`` is taken as already ordered like :attr:`joint_names`.

        Raises:
            MotionError: an unknown joint name (with the valid ones) or a wrong length.
        """
        q = np.array(base, dtype=float) if base is not None else self.neutral()
        if positions is None:
            return q
        if isinstance(positions, Mapping):
            for name, value in positions.items():
                q[self.index(name)] = float(value)
            return q
        values = np.asarray(list(positions), dtype=float)
        if values.shape != q.shape:
            raise MotionError(
                f"a configuration needs {len(q)} values ({', '.join(self.joint_names)}), got {len(values)}"
            )
        return values

    def named_state(self, group: str, name: str, base: np.ndarray | None = None) -> np.ndarray:
        """The SRDF ``<group_state>`` ``name`` of ``group`` applied to ``base``.

        Raises:
            MotionError: unknown state, with the states the group has.
        """
        state = self.semantic.group_states.get((group, name))
        if state is None:
            valid = [n for g, n in self.semantic.group_states if g == group]
            raise MotionError(f"group {group!r} has no named state {name!r}; {did_you_mean(name, valid)}")
        return self.configuration(state, base)

    def within_limits(self, q: np.ndarray, tolerance: float = 1e-9) -> bool:
        """True when every coordinate of ``q`` lies within its position limits (± ``tolerance``)."""
        return bool(np.all(q >= self.lower - tolerance) and np.all(q <= self.upper + tolerance))

    def pin_configuration(self, q: np.ndarray) -> np.ndarray:
        """Expand ``q`` (shape ``(n,)``) into pinocchio's configuration ``(nq,)``, mimics filled in."""
        return self.mimic_map @ q + self._mimic_offsets

    def new_data(self) -> pin.Data:
        """A fresh pinocchio ``Data`` (one per thread: ``Data`` is scratch space, not thread-safe)."""
        return self.pin_model.createData()


def _pin():
    import pinocchio

    return pinocchio
