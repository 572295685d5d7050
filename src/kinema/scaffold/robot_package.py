"""``kinema new config NAME --from-urdf URDF``: a config package for a robot nobody wrote for Kinema.

From a URDF (or xacro) and, optionally, its SRDF and a MuJoCo scene, this writes a package the normal
loading path reads — there is no second path for generated robots::

    NAME/package.xml
    NAME/config/config.yaml            based on kinema_base (Kinema's core behaviors and subtrees)
    NAME/description/NAME.urdf         the URDF, xacro expanded, mesh URIs as written
    NAME/description/NAME.srdf         the given SRDF, or one made from the URDF's longest chain
    NAME/description/joint_limits.yaml velocity limits from the URDF, accelerations (see below)
    NAME/description/NAME_scene.xml    the MuJoCo scene (generated, or the one given) + meshes/
    NAME/description/objects.xml       your objects in that world (a generated scene includes it)
    NAME/waypoints/waypoints.yaml      Home and the SRDF's group states, under their own names
    NAME/objectives/                   Open Gripper / Close Gripper when the robot has a gripper

What it decides, and where a user changes it (config.yaml says it again beside each value):

- the planning group: the SRDF's largest group of joints that names no other group; without an SRDF (or
  an SRDF without groups) a group ``manipulator`` over the URDF's longest chain of movable joints;
- the gripper: the movable joints outside the planning group that are no mimic of another; with one such
  joint it is the gripper (without an SRDF, the longest chain's last joint is left out of the group when
  its name says grip, finger, jaw or claw: an arm whose jaw ends the chain), open and closed from the
  SRDF group states called ``open``/``close(d)`` of a group holding it, else from its limits (a
  prismatic finger opens at its upper limit, a revolute knuckle at its lower one, a guess the notes
  say: one-jaw grippers differ). The generated Open/Close Gripper objectives read the positions from
  config.yaml (``$(config robot.gripper.open_position)``), so an edit there is all a wrong guess needs;
- the tool frame: the SRDF end effector's parent link, else the planning group's tip (the deepest link of a
  group of joints that ends with fixed ones), or the tool point fixed beyond it (a single path of fixed
  joints ending in a link named like tcp, tool, eef, frame, grasp or tip), said in a note;
- ``Home``: the first SRDF group state named ``home``, ``ready`` or ``default`` that covers the planning
  group, else the rest pose, every joint at 0 (a joint whose limits exclude 0 at the middle of its
  range), when a user can work from it; where it is near-singular, lies on the table or leaves the tool
  no room to move, the least bent pose from it that does not (:mod:`kinema.scaffold.home_pose` has the
  rule), said in a note and in config.yaml. The simulation starts there. Link pairs in collision at the
  rest pose are disabled in a generated SRDF (reason ``Default``, as MoveIt's setup assistant does); a
  given SRDF is left as it is, and a note says which pairs overlap at Home;
- accelerations: the URDF has none, so each joint's is twice its velocity limit per second.

Nothing is written when anything fails: the package is made in a temporary folder and moved into place.
"""

from __future__ import annotations

import logging
import math
import re
import shutil
import tempfile
import textwrap
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from lxml import etree

from kinema.config.robot_files import PackageIndex, ResolvedRobot, UrdfJoint, resolve_robot
from kinema.config.workspace import Workspace
from kinema.errors import KinemaError, MotionError, ScaffoldError
from kinema.motion.srdf import GroupDefinition, SemanticDescription, parse_srdf
from kinema.scaffold.home_pose import HomeChoice, home_note
from kinema.scaffold.names import check_package_name

if TYPE_CHECKING:
    from kinema.motion.robot_model import RobotModel

#: The parent of every generated package.
BASE_PACKAGE = "kinema_base"
GRIPPER_CONTROLLER = "gripper_controller"
ARM_CONTROLLER = "joint_trajectory_controller"
HOME = "Home"
#: How a user changes the generated Home, said wherever Home's choice is.
HOME_HOW_TO = (
    "To start elsewhere, give an SRDF with a group state 'home' (--srdf), or edit Home in "
    "waypoints/waypoints.yaml and the scene's keyframe 'home' (the simulation starts there)."
)
#: The last joint of a generated group's chain with such a name is the gripper, not part of the group.
GRIPPER_NAME = re.compile(r"grip|finger|jaw|claw", re.IGNORECASE)


@dataclass
class RobotPlan:
    """What the generator decided for one robot (also what ``--dry-run``-like callers can show)."""

    name: str
    robot: ResolvedRobot
    semantic: SemanticDescription
    srdf_text: str
    planning_group: str
    group_joints: list[str]
    tool_frame: str
    home: dict[str, float]
    waypoints: dict[str, dict[str, float]]
    gripper_joint: str | None = None
    gripper_open: float = 0.0
    gripper_closed: float = 0.0
    notes: list[str] = field(default_factory=list)
    #: Why Home is what it is, when the rest pose was found wanting (config.yaml says it too).
    home_note: str | None = None


def _package_index(workspace: Workspace) -> PackageIndex:
    return PackageIndex(packages={p.name: p.path for p in workspace.packages.values()})


def _chain_joints(joints: Mapping[str, UrdfJoint], base: str, tip: str) -> list[str]:
    by_child = {j.child: j for j in joints.values()}
    chain: list[str] = []
    link = tip
    while link != base:
        joint = by_child.get(link)
        if joint is None:
            raise ScaffoldError(
                f"the SRDF names a chain from {base!r} to {tip!r}, which the URDF does not have"
            )
        chain.append(joint.name)
        link = joint.parent
    return [name for name in reversed(chain) if joints[name].movable]


def _group_joints(
    name: str,
    groups: Mapping[str, GroupDefinition],
    joints: Mapping[str, UrdfJoint],
    seen: frozenset[str] = frozenset(),
) -> list[str]:
    group = groups[name]
    out: list[str] = []
    for base, tip in group.chains:
        out += _chain_joints(joints, base, tip)
    out += [j for j in group.joints if j in joints and joints[j].movable]
    by_child = {j.child: j for j in joints.values()}
    out += [by_child[link].name for link in group.links if link in by_child and by_child[link].movable]
    for sub in group.subgroups:
        if sub in groups and sub not in seen:
            out += _group_joints(sub, groups, joints, seen | {name})
    return list(dict.fromkeys(out))


def _check_srdf_names(semantic: SemanticDescription, robot: ResolvedRobot, srdf: Path) -> None:
    """Every joint and link the SRDF names must be the URDF's; one error lists them all."""
    joints = {j.name for j in robot.joints()}
    links = {j.child for j in robot.joints()} | {robot.root_link()}
    parents = {j.child: j.parent for j in robot.joints()}
    problems = []
    for group in semantic.groups.values():
        problems += [f"group {group.name!r} names joint {j!r}" for j in group.joints if j not in joints]
        problems += [f"group {group.name!r} names link {lk!r}" for lk in group.links if lk not in links]
        for base, tip in group.chains:
            unknown = [lk for lk in (base, tip) if lk not in links]
            problems += [f"group {group.name!r} chain names link {lk!r}" for lk in unknown]
            if not unknown and not _below(tip, base, parents):
                problems.append(f"group {group.name!r} chain's tip {tip!r} is not below its base {base!r}")
    for (group_name, state), values in semantic.group_states.items():
        problems += [
            f"group state {state!r} ({group_name}) names joint {j!r}" for j in values if j not in joints
        ]
    for effector in semantic.end_effectors:
        if effector.parent_link not in links:
            problems.append(f"end effector {effector.name!r} names link {effector.parent_link!r}")
    if problems:
        # The names of the kinds the problems are about, so that the right one is at hand.
        valid = [
            f" The URDF's {kind}: {', '.join(sorted(names))}"
            for kind, names in (("joints", joints), ("links", links))
            if any(f" {kind[:-1]} " in problem for problem in problems)
        ]
        raise ScaffoldError(
            f"{srdf}: the SRDF does not fit the URDF {robot.source.name}: "
            + "; ".join(problems[:8])
            + (f" (and {len(problems) - 8} more)" if len(problems) > 8 else "")
            + "."
            + ".".join(valid)
            + (". " if valid else " ")
            + "Fix the SRDF, or leave out --srdf: an SRDF is then made from the URDF (its longest chain)."
        )


def _below(tip: str, base: str, parents: Mapping[str, str]) -> bool:
    """``tip`` is ``base`` or one of its descendants (following each link's parent)."""
    link = tip
    for _ in range(len(parents) + 1):
        if link == base:
            return True
        if link not in parents:
            return False
        link = parents[link]
    return False


def _generated_srdf(
    robot: ResolvedRobot,
    group: str,
    base: str,
    tip: str,
    semantic: SemanticDescription,
    in_default: Sequence[tuple[str, str]] = (),
) -> str:
    """The SRDF of a robot without one: its longest chain as the group, and the link pairs MoveIt's setup
    assistant disables first: ``Adjacent`` (a joint's two links) and ``Default`` (``in_default``: in
    collision at Home, links that touch by design)."""
    root = etree.Element("robot", name=robot.name)
    root.append(
        etree.Comment(
            " Made by kinema new config from the URDF: the URDF's longest chain of movable joints. "
        )
    )
    element = etree.SubElement(root, "group", name=group)
    etree.SubElement(element, "chain", base_link=base, tip_link=tip)
    reasons: dict[tuple[str, ...], str] = {}
    for pair in (*semantic.disabled_collisions, *in_default):
        reasons.setdefault(tuple(sorted(pair)), "Default")
    for joint in robot.joints():
        reasons[tuple(sorted((joint.parent, joint.child)))] = "Adjacent"
    for (a, b), reason in sorted(reasons.items()):
        if a != b:
            etree.SubElement(root, "disable_collisions", link1=a, link2=b, reason=reason)
    return '<?xml version="1.0"?>\n' + etree.tostring(root, pretty_print=True, encoding="unicode")


@contextmanager
def _planning_model(robot: ResolvedRobot, srdf_text: str, notes: list[str]) -> Iterator[RobotModel | None]:
    """The robot as the planner loads it (URDF and SRDF), while a copy of its files exists (the collision
    meshes are read through the URDF); None, said in a note, when pinocchio cannot load it."""
    from kinema.motion.robot_model import RobotModel

    # The SRDF's notes were said already, at the user's file: not again at this temporary copy.
    model_log = logging.getLogger("kinema.motion.robot_model")
    was_disabled, model_log.disabled = model_log.disabled, True
    try:
        with tempfile.TemporaryDirectory() as folder:
            urdf = robot.write_urdf(Path(folder) / "robot.urdf")
            srdf = Path(folder) / "robot.srdf"
            srdf.write_text(srdf_text)
            try:
                model = RobotModel.from_urdf(urdf, srdf)
                model.collision_geometry()
            except MotionError as error:
                notes.append(f"{HOME} was not checked for collisions: {error.message}")
                model = None
            yield model
    finally:
        model_log.disabled = was_disabled


def _self_collisions(model: RobotModel, home: Mapping[str, float]) -> list[tuple[str, str]]:
    """The link pairs in collision at ``home`` (the SRDF's disabled pairs left out)."""
    from kinema.motion.collision import CollisionChecker, self_collisions

    return self_collisions(CollisionChecker(model), home)


def _choose_home(
    model: RobotModel,
    group: str,
    tool_frame: str,
    rest: Mapping[str, float],
    table_top: float,
    notes: list[str],
) -> HomeChoice | None:
    """:func:`~kinema.scaffold.home_pose.choose_home`; None, said in a note, when the model cannot tell."""
    from kinema.scaffold.home_pose import choose_home

    try:
        return choose_home(model, group, tool_frame, rest, table_top=table_top)
    except MotionError as error:
        notes.append(f"{HOME} is the rest pose, not checked for reach: {error.message}")
        return None


def _table_top(robot: ResolvedRobot, model: RobotModel) -> float:
    """The height of the generated table's top in the URDF's root frame, m: where the scene stands the
    robot, at its root link, or at the link fixed to a root named ``world`` (MuJoCo merges that one into
    its world)."""
    from kinema.motion.kinematics import fk

    if robot.root_link() != "world":
        return 0.0
    mount = next((j for j in robot.joints() if j.parent == "world" and j.kind == "fixed"), None)
    if mount is None:
        return 0.0
    return float(fk(model, model.neutral(), mount.child)[2, 3])


def _depth(joints: Mapping[str, UrdfJoint], link: str) -> int:
    """How many joints lie between ``link`` and the URDF's root."""
    parent_of = {joint.child: joint.parent for joint in joints.values()}
    depth = 0
    while link in parent_of and depth <= len(joints):
        link, depth = parent_of[link], depth + 1
    return depth


def _tool_point(joints: Mapping[str, UrdfJoint], tip: str) -> str:
    """The link fixed beyond ``tip`` that names a tool point (the SO-ARM's ``gripper_frame_link``, the
    Panda's ``panda_hand_tcp``): followed while each link has exactly one fixed child; ``tip`` itself when
    that path ends in no such name (or branches: the UR5's ``ee_link`` and ``tool0`` are left to the user)."""
    from kinema.scaffold.mjcf_scene import TOOL_POINT_NAME

    link = tip
    for _ in range(len(joints)):
        fixed = [j.child for j in joints.values() if j.parent == link and not j.movable]
        if len(fixed) != 1:
            break
        link = fixed[0]
    return link if link != tip and TOOL_POINT_NAME.search(link) else tip


def _rest(joint: UrdfJoint) -> float:
    """Where a joint rests at the generated Home: 0, or the middle of its range when 0 is outside it (the
    nearest limit is a hard stop: a Kinova's shoulder and elbow clipped to theirs fold the arm into the
    table)."""
    low, high = joint.lower, joint.upper
    if low is not None and high is not None and not low <= 0.0 <= high:
        return round((low + high) / 2.0, 6)
    return _clip(joint, 0.0)


def _clip(joint: UrdfJoint, value: float) -> float:
    low = joint.lower if joint.lower is not None else -math.inf
    high = joint.upper if joint.upper is not None else math.inf
    return min(max(value, low), high)


def plan_robot(
    name: str, urdf: Path, *, srdf: Path | None, xacro_args: Mapping[str, str] | None, index: PackageIndex
) -> RobotPlan:
    """Read the robot and decide its group, gripper, tool frame, Home and waypoints (see the module doc).

    Raises:
        ConfigError: the URDF cannot be read, xacro fails, a mesh is missing or an LFS pointer.
        ScaffoldError: no movable joints, or an SRDF naming what the URDF lacks.
    """
    from kinema.scaffold.mjcf_scene import longest_chain

    robot = resolve_robot(urdf, xacro_args=xacro_args, index=index)
    joints = {j.name: j for j in robot.joints()}
    active = [j.name for j in joints.values() if j.movable and j.mimic is None]
    if not active:
        raise ScaffoldError(
            f"{urdf}: the URDF has no movable joints (revolute, continuous or prismatic): nothing to "
            "plan or simulate"
        )
    notes: list[str] = []
    semantic = SemanticDescription()
    srdf_text = ""
    if srdf is not None:
        try:
            semantic = parse_srdf(srdf)
        except MotionError as error:
            raise ScaffoldError(str(error)) from None
        _check_srdf_names(semantic, robot, srdf)
        srdf_text = Path(srdf).read_text()
        notes += semantic.notes
    groups = {
        n: _group_joints(n, semantic.groups, joints) for n, g in semantic.groups.items() if not g.subgroups
    }
    groups = {n: js for n, js in groups.items() if js}
    if groups:
        group = max(groups, key=lambda n: len(groups[n]))
        group_joints = groups[group]
    else:
        base, tip, chain = longest_chain(robot.urdf_text)
        group = "manipulator"
        group_joints = [j for j in chain if joints[j].mimic is None]
        last = group_joints[-1]
        if len(group_joints) > 1 and GRIPPER_NAME.search(last):
            # An arm whose jaw is the chain's last joint (a Unitree Z1, an SO-100): the jaw is the gripper.
            group_joints, tip = group_joints[:-1], joints[last].parent
            notes.append(f"gripper {last!r}: the longest chain's last joint, named like a gripper")
        srdf_text = _generated_srdf(robot, group, base, tip, semantic)
        semantic = _parse_srdf_text(srdf_text)
        notes.append(f"planning group {group!r}: the URDF's longest chain, {base} → {tip}")
    effector = next((e for e in semantic.end_effectors if e.parent_link), None)
    if effector is not None:
        tool_frame = effector.parent_link
    else:
        definition = semantic.groups.get(group)
        tip_links = [t for _, t in definition.chains] if definition else []
        if tip_links:
            tool_frame = tip_links[-1]
        else:
            # A group of joints may end with fixed ones (the xArm's joint_eef): its tip is the deepest link.
            listed = [joints[j].child for j in (definition.joints if definition else ()) if j in joints]
            tool_frame = max([joints[group_joints[-1]].child, *listed], key=lambda link: _depth(joints, link))
        tool_point = _tool_point(joints, tool_frame)
        if tool_point != tool_frame:
            notes.append(
                f"tool frame {tool_point!r}: the tool point fixed to the planning group's tip {tool_frame!r}"
            )
            tool_frame = tool_point
    others = [j for j in active if j not in group_joints]
    gripper = others[0] if len(others) == 1 else None
    fixed_fingers = [j.name for j in joints.values() if not j.movable and GRIPPER_NAME.search(j.name)]
    if not others and fixed_fingers:
        notes.append(
            f"no gripper: the URDF's {', '.join(fixed_fingers[:4])} are fixed joints (a hand that cannot "
            "move); make them revolute or prismatic in the URDF, or give your own MuJoCo scene (--mjcf) and "
            "robot.gripper in config.yaml"
        )
    if len(others) > 1:
        notes.append(
            f"no gripper: {len(others)} movable joints are outside {group!r} ({', '.join(others)}); set "
            "robot.gripper in config.yaml if one of them is the gripper"
        )
    home: dict[str, float] = {n: _rest(joints[n]) for n in active}
    home_state: tuple[str, str] | None = None  # the SRDF group state Home is
    for state in ("home", "ready", "default"):
        home_state = next(
            (
                key
                for key, v in semantic.group_states.items()
                if key[1].lower() == state and set(group_joints) <= set(v)
            ),
            None,
        )
        if home_state is not None:
            found = semantic.group_states[home_state]
            home.update({k: float(v) for k, v in found.items() if k in home})
            notes.append(f"{HOME}: the SRDF group state {home_state[1]!r}")
            break
    opened = closed = 0.0
    if gripper is not None:
        joint = joints[gripper]
        low = joint.lower if joint.lower is not None else 0.0
        high = joint.upper if joint.upper is not None else 0.0
        if joint.kind == "prismatic":
            opened, closed = high, low
        else:
            opened, closed = low, high
        open_state, closed_state = semantic.gripper_positions(gripper)
        if open_state is not None:
            opened = open_state
        if closed_state is not None:
            closed = closed_state
        if joint.kind != "prismatic" and (open_state is None or closed_state is None):
            notes.append(
                f"gripper {gripper!r} is a revolute jaw: open ({opened:g}) and closed ({closed:g}) are a "
                "guess from its limits; run Open Gripper and, if it closes, swap robot.gripper.open_position "
                "and closed_position in config.yaml"
            )
        home[gripper] = opened
    generated = not groups
    rest_words = "every joint at 0" + (
        " (those whose limits exclude 0 mid-range)"
        if any(_rest(joints[n]) != 0.0 for n in group_joints)
        else ""
    )
    with _planning_model(robot, srdf_text, notes) as model:
        # As MoveIt's setup assistant does: the pairs in collision at the rest pose touch by design.
        overlapping = _self_collisions(model, home) if model is not None else []
        if overlapping and generated:
            srdf_text = _generated_srdf(robot, group, base, tip, semantic, overlapping)
            semantic = _parse_srdf_text(srdf_text)
            if model is not None:
                model.semantic = semantic
        choice = None
        if home_state is None and model is not None:
            choice = _choose_home(model, group, tool_frame, home, _table_top(robot, model), notes)
        if choice is not None and choice.changed:
            home.update(choice.positions)
            if not generated and model is not None:
                overlapping = _self_collisions(model, home)
    if overlapping and generated:
        at = "the rest pose (where Home was moved from)" if choice is not None and choice.changed else HOME
        notes.append(
            f"{len(overlapping)} link pair(s) in collision at {at} are disabled in the SRDF (reason Default, "
            f"as MoveIt's setup assistant does: links that touch by design): "
            + ", ".join(f"{a} - {b}" for a, b in overlapping)
        )
    chosen_note = home_note(choice, rest_words, HOME_HOW_TO) if choice is not None else None
    if chosen_note is not None:
        notes.append(chosen_note)
    if overlapping and not generated:
        from kinema.motion.collision import self_collision_warning

        notes.append(self_collision_warning(HOME, overlapping, "the SRDF"))
    waypoints = {HOME: dict(home)}
    for (_group, state), values in semantic.group_states.items():
        if (_group, state) == home_state and state.lower() == HOME.lower():
            continue  # "home" is Home (a "ready" or "default" it came from stays a waypoint of that name)
        waypoint = dict(home)
        for joint_name, value in values.items():
            if joint_name not in waypoint:
                continue
            waypoint[joint_name] = _clip(joints[joint_name], float(value))
            if waypoint[joint_name] != float(value):
                # The scene's keyframe is clipped by MuJoCo anyway: the waypoint says the same place.
                notes.append(
                    f"waypoint {state!r}: the SRDF gives {joint_name} = {float(value):g}, outside its "
                    f"limits; clipped to {waypoint[joint_name]:g}"
                )
        waypoints.setdefault(state, waypoint)
    return RobotPlan(
        name=name,
        robot=robot,
        semantic=semantic,
        srdf_text=srdf_text,
        planning_group=group,
        group_joints=group_joints,
        tool_frame=tool_frame,
        home=home,
        waypoints=waypoints,
        gripper_joint=gripper,
        gripper_open=opened,
        gripper_closed=closed,
        notes=notes,
        home_note=chosen_note,
    )


def _parse_srdf_text(text: str) -> SemanticDescription:
    with tempfile.NamedTemporaryFile("w", suffix=".srdf", delete=False) as handle:
        handle.write(text)
    try:
        return parse_srdf(handle.name)
    finally:
        Path(handle.name).unlink(missing_ok=True)


def _yaml_number(value: float) -> str:
    return repr(round(float(value), 6))


def _joint_limits_yaml(plan: RobotPlan) -> str:
    lines = [
        "# Velocity limits from the URDF; the URDF gives no accelerations, so each is twice the velocity",
        "# limit per second. Replace them with your robot's datasheet values.",
        "default_velocity_scaling_factor: 1.0",
        "default_acceleration_scaling_factor: 1.0",
        "joint_limits:",
    ]
    for joint in plan.robot.joints():
        if not joint.movable or joint.mimic is not None:
            continue
        velocity = joint.velocity if joint.velocity and joint.velocity > 0 else 1.0
        lines += [
            f"  {joint.name}:",
            "    has_velocity_limits: true",
            f"    max_velocity: {_yaml_number(velocity)}",
            "    has_acceleration_limits: true",
            f"    max_acceleration: {_yaml_number(2.0 * velocity)}",
        ]
    return "\n".join(lines) + "\n"


def _waypoints_yaml(plan: RobotPlan) -> str:
    others = " and the SRDF's group states" if len(plan.waypoints) > 1 else ""
    lines = [
        f"# Waypoints of {plan.name}: Home (where the simulation starts){others}.",
        "# Saved and edited by `kinema waypoint` and the UIs (MoveIt Pro's waypoint format).",
    ]
    for name, values in plan.waypoints.items():
        joint_names = list(values)
        lines += [
            f"- name: {name!r}",
            "  joint_group_names: [" + plan.planning_group + "]",
            "  joint_state:",
            "    header: {frame_id: ''}",
            "    name: [" + ", ".join(joint_names) + "]",
            "    position: [" + ", ".join(_yaml_number(values[j]) for j in joint_names) + "]",
            "    velocity: []",
            "    effort: []",
        ]
    return "\n".join(lines) + "\n"


def _gripper_objective(plan: RobotPlan, objective: str, position: float, *, grasp_check: bool = False) -> str:
    """Open Gripper / Close Gripper; Close Gripper takes ``require_grasp`` for picks (as lab_sim's does)."""
    key = "open_position" if objective == "Open Gripper" else "closed_position"
    action = '<Action ID="MoveGripperAction" position="{position}"/>'
    port = (
        f'\n      <input_port name="position" default="$(config robot.gripper.{key})">Where the gripper '
        f"goes (default: the config's robot.gripper.{key}).</input_port>"
    )
    if grasp_check:
        action = '<Action ID="MoveGripperAction" position="{position}" require_grasp="{require_grasp}"/>'
        port += (
            '\n      <input_port name="require_grasp" default="false">true for a pick: the gripper closing '
            "all the way (on nothing) fails instead of succeeding.</input_port>"
        )
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<root BTCPP_format="4" main_tree_to_execute="{objective}">
  <!-- Made by kinema new config (from the URDF): {plan.gripper_joint} to {position:g} when it was made;
       config.yaml's robot.gripper.{key} says where. -->
  <BehaviorTree ID="{objective}" _description="{objective.split()[0]} the gripper" _favorite="true">
    {action}
  </BehaviorTree>
  <TreeNodesModel>
    <SubTree ID="{objective}">{port}
      <MetadataFields>
        <Metadata subcategory="Grasping"/>
        <Metadata runnable="true"/>
      </MetadataFields>
    </SubTree>
  </TreeNodesModel>
</root>
"""


def _config_yaml(plan: RobotPlan, scene: str, source: str) -> str:
    name = plan.name
    controllers = [ARM_CONTROLLER] + ([GRIPPER_CONTROLLER] if plan.gripper_joint else [])
    text = (
        f"""#
# {name}: made by `kinema new config {name} --from-urdf {source}`.
# The schema is MoveIt Pro's config.yaml, with Kinema's hardware.simulation and robot sections.
#
based_on_package: "{BASE_PACKAGE}"

hardware:
  robot_description:
    urdf:
      package: "{name}"
      path: "description/{name}.urdf"
    srdf:
      package: "{name}"
      path: "description/{name}.srdf"
  simulation:
    mujoco_model:
      package: "{name}"
      path: "description/{scene}"
    # The simulation starts in, and resets to, this keyframe ({HOME}'s joint values).{_home_comment(plan)}
    mujoco_keyframe: "home"

ros_global_params:
  use_sim_time: True

moveit_params:
  # The default planning group of behaviors and core subtrees ({", ".join(plan.group_joints)}).
  joint_group_name: "{plan.planning_group}"
  joint_limits:
    package: "{name}"
    path: "description/joint_limits.yaml"

ros2_control:
  controllers_active_at_startup:
    - "joint_state_broadcaster"
"""
        + "".join(f'    - "{c}"\n' for c in controllers)
        + f"""
robot:
  # The frame Cartesian moves and IK place when an objective names none.
  tool_frame: "{plan.tool_frame}"
  controllers:
    {ARM_CONTROLLER}:
      type: "joint_trajectory_controller/JointTrajectoryController"
      joints: [{", ".join(plan.group_joints)}]
"""
    )
    if plan.gripper_joint:
        text += f"""    {GRIPPER_CONTROLLER}:
      type: "position_controllers/GripperActionController"
      joints: [{plan.gripper_joint}]
  gripper:
    # Serves /{GRIPPER_CONTROLLER}/gripper_cmd. Open and closed are the joint's positions.
    controller: "{GRIPPER_CONTROLLER}"
    joint: "{plan.gripper_joint}"
    open_position: {_yaml_number(plan.gripper_open)}
    closed_position: {_yaml_number(plan.gripper_closed)}
"""
    text += f"""
objectives:
  objective_library_paths:
    {name}_objectives:
      package_name: "{name}"
      relative_path: "objectives"
  waypoints_file:
    package_name: "{name}"
    relative_path: "waypoints/waypoints.yaml"
"""
    return text


def _home_comment(plan: RobotPlan) -> str:
    """config.yaml's word on how Home was chosen, when the rest pose was found wanting."""
    if plan.home_note is None:
        return ""
    lines = textwrap.wrap(plan.home_note, width=100, break_long_words=False, break_on_hyphens=False)
    return "".join(f"\n    # {line}" for line in lines)


def _package_xml(name: str, robot: str) -> str:
    return f"""<?xml version="1.0"?>
<package format="3">
  <name>{name}</name>
  <version>0.1.0</version>
  <description>Kinema config package for the robot {robot}, made from its URDF.</description>
  <maintainer email="you@example.com">you</maintainer>
  <license>Apache-2.0</license>
  <export>
    <kinema_config/>
  </export>
</package>
"""


def new_robot_package(
    name: str,
    urdf: str | Path,
    *,
    srdf: str | Path | None = None,
    mjcf: str | Path | None = None,
    xacro_args: Mapping[str, str] | None = None,
    output_dir: str | Path | None = None,
    workspace: Workspace | None = None,
    progress: Callable[[str], None] | None = None,
) -> tuple[Path, RobotPlan]:
    """Write config package ``name`` for the robot in ``urdf`` (see the module's docstring).

    Returns:
        The package folder and what was decided.

    Raises:
        ScaffoldError, ConfigError: a bad name or a taken one, unreadable files, missing meshes, an SRDF
            that does not fit; nothing is written then.
    """
    from kinema.scaffold.config_package import default_output_dir
    from kinema.scaffold.mjcf_scene import generate_scene

    say = progress or (lambda _text: None)
    workspace = workspace if workspace is not None else Workspace.discover()
    check_package_name(name)
    if workspace.has_package(name):
        existing = workspace.package(name)
        raise ScaffoldError(f"a package named {name!r} already exists ({existing.path}); choose another name")
    target_dir = Path(output_dir) if output_dir is not None else default_output_dir(workspace)
    target = target_dir / name
    if target.exists():
        raise ScaffoldError(f"{target} already exists; choose another name or remove it")
    index = _package_index(workspace)
    urdf_path = _locate(urdf, index)
    srdf_path, mjcf_path = _locate(srdf, index), _locate(mjcf, index)
    for label, given in (("URDF", urdf_path), ("SRDF", srdf_path), ("MuJoCo scene", mjcf_path)):
        if given is not None and not given.is_file():
            raise ScaffoldError(f"{label} file not found: {given}")
    assert urdf_path is not None
    say(f"reading {urdf_path.name}")
    plan = plan_robot(name, urdf_path, srdf=srdf_path, xacro_args=xacro_args, index=index)
    target_dir.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{name}-", dir=target_dir))
    try:
        description = staging / "description"
        description.mkdir()
        (description / f"{name}.urdf").write_text(
            '<?xml version="1.0"?>\n' + _strip_declaration(plan.robot.urdf_text)
        )
        (description / f"{name}.srdf").write_text(plan.srdf_text)
        (description / "joint_limits.yaml").write_text(_joint_limits_yaml(plan))
        if mjcf_path is not None:
            scene = _copy_scene(mjcf_path, description)
        else:
            say("generating the MuJoCo scene (meshes are converted once)")
            keyframes = {n.lower().replace(" ", "_"): v for n, v in plan.waypoints.items() if n != HOME}
            path = generate_scene(
                plan.robot,
                description,
                name=name,
                home=plan.home,
                keyframes=keyframes,
                disabled_collisions=[tuple(sorted(p)) for p in plan.semantic.disabled_collisions],  # type: ignore[misc]
                notes=plan.notes,
            )
            scene = path.name
            _add_objects_include(path)
            if plan.gripper_joint:
                _grip_firmly(path, plan.gripper_joint, plan.gripper_open, plan.gripper_closed)
        (staging / "waypoints").mkdir()
        (staging / "waypoints" / "waypoints.yaml").write_text(_waypoints_yaml(plan))
        (staging / "objectives").mkdir()
        if plan.gripper_joint:
            (staging / "objectives" / "open_gripper.xml").write_text(
                _gripper_objective(plan, "Open Gripper", plan.gripper_open)
            )
            (staging / "objectives" / "close_gripper.xml").write_text(
                _gripper_objective(plan, "Close Gripper", plan.gripper_closed, grasp_check=True)
            )
        (staging / "config").mkdir()
        (staging / "config" / "config.yaml").write_text(_config_yaml(plan, scene, str(urdf)))
        (staging / "package.xml").write_text(_package_xml(name, plan.robot.name))
        staging.rename(target)
    except (KinemaError, OSError) as error:
        shutil.rmtree(staging, ignore_errors=True)
        if isinstance(error, KinemaError):
            raise
        raise ScaffoldError(f"cannot write {target}: {error}") from error
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return target, plan


OBJECTS_FILE = "objects.xml"
_OBJECTS_TEXT = """<mujoco>
  <!--
    Your objects in the simulated world: put bodies inside <worldbody> (a <freejoint/> makes one movable,
    e.g. a cube to pick). The robot stands on the table top at z = 0, the table reaching in front of it
    along +x. The scene includes this file; it is yours to edit (kinema new config never rewrites it).
  -->
  <worldbody>
  </worldbody>
</mujoco>
"""


def _add_objects_include(scene: Path) -> None:
    """Make the generated scene include ``objects.xml`` (the user's objects), after the robot's bodies so
    the keyframes' joint values keep their places."""
    tree = etree.parse(str(scene))
    root = tree.getroot()
    worldbody = root.find("worldbody")
    include = etree.Element("include", file=OBJECTS_FILE)
    if worldbody is not None:
        worldbody.addnext(include)
    else:
        root.append(include)
    scene.write_text(etree.tostring(root, encoding="unicode") + "\n")
    (scene.parent / OBJECTS_FILE).write_text(_OBJECTS_TEXT)


#: Share of the gripper's effort limit it squeezes with when closed on an object half as wide as it opens.
GRIP_SHARE = 0.05


def _grip_firmly(scene: Path, joint: str, opened: float, closed: float) -> None:
    """Make the gripper's servo squeeze: a servo tuned for tracking, like the arm's, presses a held
    object with under a newton, and MuJoCo's soft contacts let such a grasp creep until the object falls.

    The gain is chosen so that closing on an object half as wide as the gripper opens presses with
    GRIP_SHARE of the actuator's force limit; the damping keeps the servo's damping ratio.
    """
    tree = etree.parse(str(scene))
    for actuator in tree.getroot().iter("position"):
        if actuator.get("joint") != joint:
            continue
        limits = [abs(float(v)) for v in (actuator.get("forcerange") or "0 0").split()]
        force = max(limits) if limits else 0.0
        travel = abs(opened - closed) / 2.0
        old_kp = float(actuator.get("kp") or 0.0)
        if force <= 0.0 or travel <= 0.0 or old_kp <= 0.0:
            return
        kp = max(old_kp, GRIP_SHARE * force / travel)
        kv = float(actuator.get("kv") or 0.0) * math.sqrt(kp / old_kp)
        actuator.set("kp", f"{kp:.6g}")
        actuator.set("kv", f"{kv:.6g}")
    scene.write_text(etree.tostring(tree.getroot(), encoding="unicode") + "\n")


def _locate(given: str | Path | None, index: PackageIndex) -> Path | None:
    """A path, or a ``package://PKG/PATH`` URI found through ``index`` (installed description packages,
    the workspace, ROS_PACKAGE_PATH, AMENT_PREFIX_PATH)."""
    if given is None:
        return None
    text = str(given)
    if text.startswith("package://"):
        from kinema.config.robot_files import resolve_uri

        return resolve_uri(text, base_dir=Path.cwd(), index=index)
    return Path(given)


def _strip_declaration(text: str) -> str:
    stripped = text.lstrip()
    if stripped.startswith("<?xml"):
        return stripped[stripped.index("?>") + 2 :].lstrip()
    return stripped


def _copy_scene(mjcf: Path, description: Path) -> str:
    """Use the given MuJoCo scene: its folder (with its assets) is copied into ``description/mjcf/``."""
    destination = description / "mjcf"
    shutil.copytree(mjcf.parent, destination)
    return f"mjcf/{mjcf.name}"
