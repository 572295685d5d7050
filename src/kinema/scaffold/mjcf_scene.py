"""A MuJoCo scene generated from a URDF: the robot standing on a table, position-controlled, ready to run.

:func:`generate_scene` writes ``<out_dir>/<name>_scene.xml`` and ``<out_dir>/meshes/`` (the robot's meshes,
converted where MuJoCo cannot read them, referenced relatively so the folder can be moved). The robot is
imported with MuJoCo's own URDF parser (``mujoco.MjSpec.from_string``), which gets joint frames, inertias,
limits and mimic joints right, and the spec is then edited and written with ``MjSpec.to_xml``:

- The URDF gets a ``<mujoco><compiler fusestatic="false" discardvisual="false"/></mujoco>`` element, so
  every link stays a body named like the link (the root link too: fused into the world, the planner would
  see the robot's own base as an obstacle) and visual geoms are kept.
- Geoms: visuals are group 2 with ``contype``/``conaffinity`` 0, coloured by the URDF material or else by
  the colour recorded when the mesh was converted; collision geoms are group 3 (hidden by the viewer's
  defaults, shown with its group toggles) and collide.
- Bodies: ``gravcomp="1"`` on every robot body (the driver's position control then needs no gravity
  model); a moving body without mass gets a tiny one (MuJoCo refuses massless moving bodies).
- Contacts are excluded between links the planner calls adjacent (see :func:`adjacent_link_pairs`), as
  MoveIt's setup assistant does, and between the root link and the table it is bolted to.
- Actuators: one ``<position>`` per movable non-mimic joint, named like the joint (the driver matches
  them by name), ``ctrlrange`` = the joint limits, ``forcerange`` = the URDF effort. Gains follow one rule:
  with ``m`` the joint's diagonal of the joint-space inertia matrix at home (armature included), the
  joint is a critically damped second-order system of natural frequency :data:`NATURAL_FREQUENCY`:
  ``kp = m·ω²``, ``kv = 2·m·ω``. ω·dt = 0.08 at the 2 ms step keeps the explicit part of the integration
  far from its stability bound, the implicit integrator takes the damping, and light wrist joints get
  gains as soft as heavy shoulders are stiff, so every joint settles in about 0.1 s.
- Joints get ``armature`` (rotor inertia, which real geared joints have and which keeps the lightest
  links' inertia from collapsing) and the URDF's damping up to a quarter of the servo's ``kv``
  (:data:`DAMPING_SHARE`), but not its friction: a real arm's drive controllers overcome both, and a
  position servo with neither integral nor feed-forward terms would stop short by ``friction / kp`` and
  lag a moving target by ``damping · v / kp`` (the xArm7's URDF: 0.06 rad short, 0.3 rad behind).
- URDF ``<mimic>`` joints become joint equality constraints ``follower = offset + multiplier·leader``
  (MuJoCo's import makes them; their coefficients are checked and their solref stiffened) with no actuator.
- The world: a floor, a light, a table (a box body named ``table``) whose top the robot's base stands on
  at the world origin — so the world frame is the robot's base frame, and the floor lies below at
  ``-table height`` — reaching in front of the robot (its +x) over about its reach, and a camera named
  ``scene_camera`` looking at the robot from the front.
- Keyframes ``home`` and the caller's, with ``qpos`` and ``ctrl`` filled, mimic followers following.
"""

from __future__ import annotations

import re
import shutil
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from lxml import etree

from kinema.config.robot_files import (
    ResolvedRobot,
    UrdfJoint,
    convert_mesh,
    converted_mesh_rgba,
    default_mesh_cache,
    parse_joints,
    root_link,
)
from kinema.errors import ScaffoldError, did_you_mean

TIMESTEP = 0.002
"""The physics step of generated scenes, s (Kinema's scenes all use 2 ms)."""

NATURAL_FREQUENCY = 40.0
"""ω of every position servo, rad/s (about 6 Hz): see the module docstring for the gain rule."""

DAMPING_SHARE = 0.25
"""The most of a URDF joint's damping a scene keeps, as a share of its servo's ``kv`` (see generate_scene)."""

ARMATURE_REVOLUTE = 0.01
"""Rotor inertia added to revolute joints, kg·m²."""

ARMATURE_PRISMATIC = 0.01
"""Reflected mass added to prismatic joints, kg."""

TINY_MASS = 1e-3
TINY_INERTIA = 1e-6
"""Mass (kg) and principal inertia (kg·m²) given to a moving link the URDF gives none."""

TABLE_HEIGHT = 0.75
"""Height of the table top above the floor, m."""

VISUAL_GROUP = 2
COLLISION_GROUP = 3


def _mesh_file_name(source: Path, converted: Path) -> str:
    """A unique, stable name in ``meshes/``: converted files already carry their content hash."""
    if converted != source:
        return converted.name
    import hashlib

    digest = hashlib.sha256(source.read_bytes()).hexdigest()[:12]
    return f"{source.stem}-{digest}{source.suffix.lower()}"


def _urdf_material_colours(urdf_text: str) -> dict[tuple[str, int], tuple[float, ...]]:
    """``(link, index of its <visual>) → rgba`` from ``<material><color>`` (inline or by a top-level name)."""
    root = etree.fromstring(urdf_text.encode("utf-8"))
    named: dict[str, tuple[float, ...]] = {}
    for material in root.findall("material"):
        colour = material.find("color")
        if colour is not None and colour.get("rgba"):
            named[material.get("name", "")] = tuple(float(v) for v in colour.get("rgba", "").split())
    colours: dict[tuple[str, int], tuple[float, ...]] = {}
    for link in root.findall("link"):
        for i, visual in enumerate(link.findall("visual")):
            material = visual.find("material")
            if material is None:
                continue
            colour = material.find("color")
            if colour is not None and colour.get("rgba"):
                colours[(link.get("name", ""), i)] = tuple(float(v) for v in colour.get("rgba", "").split())
            elif material.get("name") in named:
                colours[(link.get("name", ""), i)] = named[material.get("name", "")]
    return colours


def rigid_groups(urdf_text: str) -> dict[str, str]:
    """link → the link heading its rigid group (links joined by fixed joints move as one)."""
    joints = parse_joints(urdf_text)
    parent_of = {j.child: j for j in joints}
    head: dict[str, str] = {}

    def find(link: str) -> str:
        if link not in head:
            joint = parent_of.get(link)
            head[link] = find(joint.parent) if joint is not None and joint.kind == "fixed" else link
        return head[link]

    links = {j.child for j in joints} | {j.parent for j in joints} | {root_link(urdf_text)}
    return {link: find(link) for link in links}


def adjacent_link_pairs(urdf_text: str) -> set[frozenset[str]]:
    """Link pairs that touch by construction: rigidly joined, or one joint apart once fixed joints merge.

    MoveIt's setup assistant disables these pairs as "Adjacent"; the generated scene excludes their contacts
    and the home-pose check ignores them.
    """
    group = rigid_groups(urdf_text)
    members: dict[str, list[str]] = {}
    for link, head in group.items():
        members.setdefault(head, []).append(link)
    pairs: set[frozenset[str]] = set()
    for links in members.values():
        pairs.update(frozenset((a, b)) for a in links for b in links if a != b)
    for joint in parse_joints(urdf_text):
        if joint.kind == "fixed":
            continue
        for a in members[group[joint.parent]]:
            for b in members[group[joint.child]]:
                pairs.add(frozenset((a, b)))
    return pairs


TOOL_POINT_WORDS = ("tcp", "ee_link", "tool", "grasp", "eef", "end_effector", "gripper", "tip", "frame")
"""Words of a link name that say it is where the tool works, strongest first (a TCP, a flange's tool
frame, a gripper's base; a bare ``frame`` last: the PR2's palm carries an ``led_frame`` beside its
``tool_frame``)."""
TOOL_POINT_NAME = re.compile("|".join(TOOL_POINT_WORDS), re.IGNORECASE)


def _tool_point_rank(link: str) -> int:
    """How strongly ``link``'s name says tool point (lower is stronger; ``len(TOOL_POINT_WORDS)``: not)."""
    lowered = link.lower()
    return next((i for i, word in enumerate(TOOL_POINT_WORDS) if word in lowered), len(TOOL_POINT_WORDS))


def longest_chain(urdf_text: str) -> tuple[str, str, list[str]]:
    """``(base_link, tip_link, joints)``: a planning group for a URDF that comes without an SRDF.

    The chain of movable joints with the most joints, from the root or from a link where the tree branches
    into two or more movable joints, and stopping at such a link (a hand whose fingers are not part of the
    arm: the Panda's chain ends at ``panda_hand``; a mobile manipulator's arm starts at its torso, where
    the head branches off). Mimic followers do not count. The base is the parent link of the first
    joint (``base_link`` rather than a ``world`` link fixed above it); the tip is carried on through fixed
    joints to the last link (a flange or TCP frame); where they branch, only into a child named like a tool
    point (:data:`TOOL_POINT_WORDS`), the strongest such.
    Among equally long chains the first in document order wins.

    Raises:
        ScaffoldError: the URDF has no movable joint.
    """
    joints = parse_joints(urdf_text)
    root = root_link(urdf_text)
    children: dict[str, list[UrdfJoint]] = {}
    for joint in joints:
        children.setdefault(joint.parent, []).append(joint)

    def counts(joint: UrdfJoint) -> bool:
        return joint.movable and joint.mimic is None

    def branches(link: str) -> bool:
        return sum(1 for j in children.get(link, []) if j.movable) >= 2

    best: tuple[int, list[UrdfJoint]] = (0, [])

    def walk(link: str, path: list[UrdfJoint], movable: int) -> None:
        nonlocal best
        if movable > best[0]:
            best = (movable, list(path))
        if movable > 0 and branches(link):
            # A chain ends where the tree branches (a hand into its fingers), and new ones start there: a
            # mobile manipulator's torso branches into its arms and head, a humanoid's into its limbs.
            path, movable = [], 0
        for joint in children.get(link, []):
            path.append(joint)
            walk(joint.child, path, movable + counts(joint))
            path.pop()

    walk(root, [], 0)
    count, path = best
    if count == 0:
        raise ScaffoldError("the URDF has no movable joint: there is nothing to plan for")
    movable = [j for j in path if counts(j)]
    tip = movable[-1].child
    # Carry the tip on through fixed joints (panda_hand → panda_hand_tcp, wrist_3_link → ee_link). Where
    # they branch, only into a link named like a tool point: Baxter's hand carries a camera, a range
    # sensor and an accelerometer beside its gripper.
    while fixed := [j for j in children.get(tip, []) if j.kind == "fixed"]:
        if len(fixed) > 1:
            fixed = sorted(
                (j for j in fixed if TOOL_POINT_NAME.search(j.child)), key=lambda j: _tool_point_rank(j.child)
            )
            if not fixed:
                break
        tip = fixed[0].child
    return movable[0].parent, tip, [j.name for j in movable]


def _clip(value: float, joint: UrdfJoint) -> float:
    if joint.kind != "continuous" and joint.lower is not None and joint.upper is not None:
        return min(max(value, joint.lower), joint.upper)
    return value


def _optical_frame_quat(position: np.ndarray, target: np.ndarray) -> list[float]:
    """The quaternion of an optical frame (z forward, x right, y down) at ``position`` facing ``target``."""
    import mujoco

    forward = target - position
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)
    matrix = np.column_stack([right, down, forward])
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, matrix.flatten())
    return [float(v) for v in quat]


def _joint_values(
    name: str,
    values: Mapping[str, float] | None,
    joints: list[UrdfJoint],
) -> dict[str, float]:
    """Every movable joint's value: those given (mimic followers derived), the rest 0 clipped into limits."""
    by_name = {j.name: j for j in joints if j.movable}
    values = dict(values or {})
    unknown = [k for k in values if k not in by_name]
    if unknown:
        raise ScaffoldError(
            f"keyframe {name!r} sets {unknown[0]!r}, which is not a movable joint of the robot; "
            f"{did_you_mean(unknown[0], by_name)}"
        )
    result = {joint: _clip(float(values.get(joint, 0.0)), info) for joint, info in by_name.items()}
    for joint, info in by_name.items():
        if info.mimic is not None and info.mimic[0] in result and joint not in values:
            leader, multiplier, offset = info.mimic
            result[joint] = _clip(offset + multiplier * result[leader], info)
    return result


def generate_scene(
    robot: ResolvedRobot,
    out_dir: str | Path,
    *,
    name: str | None = None,
    home: Mapping[str, float] | None = None,
    keyframes: Mapping[str, Mapping[str, float]] | None = None,
    table: bool = True,
    disabled_collisions: Iterable[tuple[str, str]] = (),
    mesh_cache: str | Path | None = None,
    notes: list[str] | None = None,
) -> Path:
    """Write a MuJoCo scene for ``robot`` to ``<out_dir>/<name>_scene.xml``; return its path.

    Args:
        robot: the resolved robot (meshes found and checked).
        out_dir: the folder to write the scene and its ``meshes/`` folder into (created).
        name: the scene's name (default: the robot's).
        home: joint values of the ``home`` keyframe; joints not given are 0, clipped into their limits.
        keyframes: further named keyframes, each joint → value like ``home``.
        table: whether to put the robot on a table (without one it stands on the floor at the origin).
        disabled_collisions: link pairs whose contacts to exclude besides the adjacent ones (an SRDF's
            ``disable_collisions``).
        mesh_cache: where converted meshes are cached between runs (default: the user's cache folder,
            :func:`~kinema.config.robot_files.default_mesh_cache`).
        notes: what the scene decided that a user should hear is appended here (link pairs whose
            contacts it excludes because their convex hulls overlap at Home).

    Raises:
        ScaffoldError: a keyframe names an unknown joint, or MuJoCo cannot compile the robot.
        ConfigError: a mesh cannot be converted.
    """
    import mujoco

    out_dir = Path(out_dir)
    name = name or robot.name
    mesh_dir = out_dir / "meshes"
    mesh_dir.mkdir(parents=True, exist_ok=True)
    cache = Path(mesh_cache) if mesh_cache is not None else default_mesh_cache()

    # Meshes into meshes/, under names unique by content.
    file_names: dict[str, str] = {}
    mesh_colour: dict[str, tuple[float, float, float, float]] = {}
    for reference in robot.meshes:
        if str(reference.path) in file_names:
            continue
        converted = convert_mesh(reference.path, cache)
        file_name = _mesh_file_name(reference.path, converted)
        target = mesh_dir / file_name
        if not target.exists():
            shutil.copyfile(converted, target)
        file_names[str(reference.path)] = file_name
        rgba = converted_mesh_rgba(converted)
        if rgba is not None:
            mesh_colour[Path(file_name).stem] = rgba

    urdf = etree.fromstring(robot.urdf_with_paths(file_names).encode("utf-8"))
    extension = etree.Element("mujoco")
    etree.SubElement(
        extension,
        "compiler",
        fusestatic="false",
        discardvisual="false",
        strippath="false",
        meshdir=str(mesh_dir.resolve()),
        angle="radian",
        autolimits="true",
    )
    urdf.insert(0, extension)
    _give_moving_links_mass(urdf)
    repaired = _make_inertias_physical(urdf)
    if repaired and notes is not None:
        notes.append(
            f"{len(repaired)} link(s) of the URDF have an inertia no rigid body has (a principal moment of 0 "
            "or less, or one larger than the other two together); the MuJoCo scene uses the nearest one that "
            "is: " + ", ".join(repaired[:6]) + (f" (+{len(repaired) - 6} more)" if len(repaired) > 6 else "")
        )
    try:
        spec = mujoco.MjSpec.from_string(etree.tostring(urdf, encoding="unicode"))
    except ValueError as exc:
        raise ScaffoldError(f"MuJoCo cannot import the URDF {robot.source}: {exc}") from None
    spec.modelname = name

    joints = parse_joints(robot.urdf_text)
    joint_by_name = {j.name: j for j in joints}
    base = root_link(robot.urdf_text)
    link_colours = _urdf_material_colours(robot.urdf_text)

    spec.option.timestep = TIMESTEP
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = 10
    # MuJoCo's soft contacts let a held object creep out of a grasp over a few minutes of simulated
    # time (it falls out of a gripper standing still); the no-slip pass stops that, as MoveIt Pro's
    # lab_sim scene does with the same setting.
    spec.option.noslip_iterations = 3

    robot_bodies = [b for b in spec.bodies if b.name and b.name != "world"]
    for body in robot_bodies:
        body.gravcomp = 1.0
        visual_index = 0
        for geom in body.geoms:
            if geom.contype == 0 and geom.conaffinity == 0:
                geom.group = VISUAL_GROUP
                colour = link_colours.get((body.name, visual_index))
                if colour is None and geom.type == mujoco.mjtGeom.mjGEOM_MESH:
                    colour = mesh_colour.get(geom.meshname)
                if colour is not None:
                    geom.rgba = list(colour)
                geom.density = 0  # visual geoms carry no mass (inertias come from the URDF)
                visual_index += 1
            else:
                geom.group = COLLISION_GROUP
                geom.rgba = [0.6, 0.4, 0.8, 0.5]

    for joint in spec.joints:
        info = joint_by_name.get(joint.name)
        if info is None:
            continue
        joint.armature = ARMATURE_PRISMATIC if info.kind == "prismatic" else ARMATURE_REVOLUTE
        joint.damping = [max(info.damping, 0.0), 0.0, 0.0]
        # A real drive's controller overcomes its joint's friction; a servo without an integral term
        # would stop short of its target by friction / kp (the xArm's 1 N·m: 0.06 rad on its wrist).
        joint.frictionloss = 0.0

    # Mimic joints: MuJoCo's URDF import makes the equality constraints; keep them right and stiff.
    existing = {(e.name1, e.name2): e for e in spec.equalities if e.type == mujoco.mjtEq.mjEQ_JOINT}
    for info in joints:
        if info.mimic is None or not info.movable:
            continue
        leader, multiplier, offset = info.mimic
        if leader not in joint_by_name:
            raise ScaffoldError(
                f"joint {info.name!r} mimics {leader!r}, which the URDF does not have; "
                f"{did_you_mean(leader, joint_by_name)}"
            )
        equality = existing.get((info.name, leader))
        if equality is None:
            equality = spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, name1=info.name, name2=leader)
        equality.name = f"{info.name}_mimics_{leader}"
        data = np.zeros(len(equality.data))
        data[0], data[1] = offset, multiplier
        equality.data = data
        equality.solref = [0.004, 1.0]

    # Contacts the planner would not check either.
    excluded = {pair for pair in adjacent_link_pairs(robot.urdf_text)}
    excluded.update(frozenset(pair) for pair in disabled_collisions if len(set(pair)) == 2)
    body_names = {b.name for b in robot_bodies}
    for pair in sorted(excluded, key=sorted):
        a, b = sorted(pair)
        if a in body_names and b in body_names:
            spec.add_exclude(bodyname1=a, bodyname2=b)

    actuated = [j for j in joints if j.movable and j.mimic is None]
    # Inertia at home decides the gains: compile once without actuators to read it.
    home_values = _joint_values("home", home, joints)
    try:
        model = spec.compile()
    except ValueError as exc:
        raise ScaffoldError(f"MuJoCo cannot compile the robot from {robot.source}: {exc}") from None
    joint_order = [model.joint(i).name for i in range(model.njnt)]
    data_ = mujoco.MjData(model)
    for i, joint_name in enumerate(joint_order):
        if joint_name in home_values:
            data_.qpos[model.jnt_qposadr[i]] = home_values[joint_name]
    mujoco.mj_forward(model, data_)
    # MuJoCo collides meshes as their convex hulls, fuller than the meshes the planner checks: two links
    # that only touch at Home in the planner's eyes (a Baxter's shoulder against its torso) overlap here,
    # push each other away from Home and make every trajectory miss its tolerance. They touch by design.
    overlapping = _robot_contacts(model, data_, body_names)
    for a, b in overlapping:
        spec.add_exclude(bodyname1=a, bodyname2=b)
    if overlapping and notes is not None:
        notes.append(
            f"the MuJoCo scene excludes contacts between {len(overlapping)} link pair(s) that overlap at "
            "Home as MuJoCo's convex hulls (the planner checks the meshes): "
            + ", ".join(f"{a} - {b}" for a, b in overlapping)
        )
    inertia_matrix = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data_, inertia_matrix)  # MuJoCo 4: (m, d, dst); MjData.qM is gone
    groups = rigid_groups(robot.urdf_text)
    mounted = [link for link, head in groups.items() if head == groups[base] and link in body_names]
    # Where the robot stands: the root link, or the first body fixed to it when the root is a URDF
    # "world" link (MuJoCo merges that into its world body, with the mount's offset kept).
    stand = np.array(data_.xpos[min(model.body(link).id for link in mounted)]) if mounted else np.zeros(3)
    reach = _reach(model, data_, stand)

    spec_joints = {joint.name: joint for joint in spec.joints}
    for info in actuated:
        joint_id = model.joint(info.name).id
        dof = int(model.jnt_dofadr[joint_id])
        inertia = float(inertia_matrix[dof, dof])
        actuator = spec.add_actuator(name=info.name, target=info.name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        omega = NATURAL_FREQUENCY
        kv = 2.0 * inertia * omega
        actuator.set_to_position(kp=inertia * omega**2, kv=kv)
        # The URDF's damping, up to a quarter of the servo's own: more makes the servo lag behind a moving
        # target by damping·v/kp (the xArm's 10 N·m·s/rad: 0.3 rad at 1 rad/s), which a real drive's
        # controller compensates and this servo cannot.
        spec_joint = spec_joints[info.name]
        spec_joint.damping = [min(float(spec_joint.damping[0]), DAMPING_SHARE * kv), 0.0, 0.0]
        if bool(model.jnt_limited[joint_id]):
            low, high = (float(v) for v in model.jnt_range[joint_id])
            actuator.ctrlrange = [low, high]
            actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        if info.effort:
            actuator.forcerange = [-info.effort, info.effort]
            actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE

    _add_world(spec, mounted=mounted, stand=stand, reach=reach, table=table)

    named = {"home": home or {}, **(keyframes or {})}
    for key_name, values in named.items():
        joint_values = _joint_values(key_name, values, joints)
        qpos = np.zeros(model.nq)
        for i, joint_name in enumerate(joint_order):
            if joint_name in joint_values:
                qpos[model.jnt_qposadr[i]] = joint_values[joint_name]
        ctrl = [joint_values[j.name] for j in actuated]
        spec.add_key(name=key_name, qpos=list(qpos), ctrl=ctrl)

    try:
        spec.compile()
    except ValueError as exc:
        raise ScaffoldError(f"MuJoCo cannot compile the generated scene: {exc}") from None
    # to_xml compiles again, reading the meshes: the relative meshdir goes in afterwards.
    document = etree.fromstring(spec.to_xml().encode("utf-8"))
    compiler = document.find("compiler")
    if compiler is None:
        compiler = etree.SubElement(document, "compiler")
        document.insert(0, compiler)
    compiler.set("meshdir", "meshes")
    # The written inertias are rounded: one at the edge of A + B >= C (TIAGo's arm_1_link) would fail to load.
    compiler.set("balanceinertia", "true")
    option = document.find("option")
    if option is None:
        option = etree.Element("option")
        compiler.addnext(option)
    option.set("timestep", str(TIMESTEP))  # to_xml leaves defaults out; the step is worth reading
    _write_position_shorthand(document)
    tree = document.getroottree()
    document.addprevious(
        etree.Comment(f" Generated by kinema from {robot.source.name}; regenerate rather than edit. ")
    )
    scene = out_dir / f"{name}_scene.xml"
    from kinema.config.atomic_write import atomic_write_text

    atomic_write_text(scene, etree.tostring(tree, encoding="unicode", pretty_print=True) + "\n")
    return scene


def _write_position_shorthand(document: etree._Element) -> None:
    """Write the servos as ``<position kp kv>``, as a person would, rather than MuJoCo 4's ``<general>`` form.

    ``MjSpec.to_xml`` writes every actuator as ``<general gainprm biasprm biastype="affine">``; the
    ``<position>`` shorthand compiles to the same numbers (a test compares them) and reads like lab_sim.
    """
    actuators = document.find("actuator")
    if actuators is None:
        return
    for general in actuators.findall("general"):
        gain = general.get("gainprm", "").split()
        bias = general.get("biasprm", "").split()
        if general.get("biastype") != "affine" or len(gain) != 1 or len(bias) != 3 or bias[0] != "0":
            continue
        if float(bias[1]) != -float(gain[0]):
            continue
        position = etree.Element("position", name=general.get("name", ""), joint=general.get("joint", ""))
        position.set("kp", gain[0])
        position.set("kv", repr(-float(bias[2])) if float(bias[2]) else "0")
        for attribute in ("ctrlrange", "forcerange"):
            if general.get(attribute):
                position.set(attribute, general.get(attribute, ""))
        position.tail = general.tail
        actuators.replace(general, position)


def _give_moving_links_mass(urdf: etree._Element) -> None:
    """A tiny inertia for links that move without one (MuJoCo refuses massless moving bodies).

    Only links whose parent joint moves: a massless link fixed to another (a tool frame) or the root is a
    static body MuJoCo accepts as it is, and adding mass there would change the robot's dynamics.
    """
    moving = {
        child.get("link", "")
        for joint in urdf.findall("joint")
        if joint.get("type") in ("revolute", "continuous", "prismatic")
        for child in joint.findall("child")
    }
    for link in urdf.findall("link"):
        if link.get("name") not in moving:
            continue
        inertial = link.find("inertial")
        mass = inertial.find("mass") if inertial is not None else None
        try:
            massless = mass is None or float(mass.get("value", "0")) <= 0.0
        except ValueError:
            massless = True
        if not massless:
            continue
        if inertial is not None:
            link.remove(inertial)
        inertial = etree.SubElement(link, "inertial")
        etree.SubElement(inertial, "mass", value=repr(TINY_MASS))
        etree.SubElement(
            inertial,
            "inertia",
            ixx=repr(TINY_INERTIA),
            iyy=repr(TINY_INERTIA),
            izz=repr(TINY_INERTIA),
            ixy="0",
            ixz="0",
            iyz="0",
        )


def _make_inertias_physical(urdf: etree._Element) -> list[str]:
    """Repair the inertias MuJoCo refuses (not positive definite, or a principal moment above the sum of
    the other two: the PR2's and TIAGo's URDFs have both), keeping their principal axes; returns the links
    repaired. Valid inertias are left exactly as written."""
    repaired = []
    for link in urdf.findall("link"):
        inertia = link.find("inertial/inertia")
        if inertia is None:
            continue
        try:
            xx, yy, zz, xy, xz, yz = (
                float(inertia.get(key, "0")) for key in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
            )
        except ValueError:
            continue
        matrix = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
        moments, axes = np.linalg.eigh(matrix)
        floor = max(float(moments.max()) * 1e-3, 1e-12)
        fixed = np.where(moments > 0.0, moments, floor)
        for _ in range(3):  # each principal moment at most the sum of the other two
            for index in range(3):
                others = fixed.sum() - fixed[index]
                if fixed[index] > others * (1.0 + 1e-9):
                    fixed[np.argmin(fixed)] += (fixed[index] - others) * (1.0 + 1e-6)
        if np.array_equal(fixed, moments):
            continue
        rebuilt = axes @ np.diag(fixed) @ axes.T
        for key, (row, column) in {
            "ixx": (0, 0),
            "iyy": (1, 1),
            "izz": (2, 2),
            "ixy": (0, 1),
            "ixz": (0, 2),
            "iyz": (1, 2),
        }.items():
            inertia.set(key, repr(float(rebuilt[row, column])))
        repaired.append(link.get("name", ""))
    return repaired


def _robot_contacts(model: Any, data: Any, links: Iterable[str]) -> list[tuple[str, str]]:
    """The pairs of the robot's links in contact in ``data`` (after ``mj_forward``; sorted, each once)."""
    robot = {model.body(name).id for name in links if name != "world"}
    pairs: set[tuple[str, str]] = set()
    for contact in data.contact[: data.ncon]:
        a, b = int(model.geom_bodyid[contact.geom1]), int(model.geom_bodyid[contact.geom2])
        if a in robot and b in robot and a != b:
            first, second = sorted((model.body(a).name, model.body(b).name))
            pairs.add((first, second))
    return sorted(pairs)


def _reach(model: Any, data: Any, stand: np.ndarray) -> float:
    """How far the robot's bodies are from where it stands at the pose in ``data``, m (≥ 0.3)."""
    distances = [float(np.linalg.norm(data.xpos[b] - stand)) for b in range(1, model.nbody)]
    return max([0.3, *distances])


def _add_world(spec: Any, *, mounted: list[str], stand: np.ndarray, reach: float, table: bool) -> None:
    """Floor, light, table and camera around a robot standing at ``stand`` (the world origin, usually)."""
    import mujoco

    spec.visual.global_.offwidth = 640
    spec.visual.global_.offheight = 480
    x, y, z = (float(v) for v in stand)
    floor_z = z - TABLE_HEIGHT if table else z
    spec.add_texture(
        name="sky",
        type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
        rgb1=[0.75, 0.8, 0.85],
        rgb2=[0.35, 0.4, 0.45],
        width=128,
        height=128,
    )
    spec.add_texture(
        name="grid",
        type=mujoco.mjtTexture.mjTEXTURE_2D,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
        rgb1=[0.82, 0.82, 0.84],
        rgb2=[0.74, 0.74, 0.76],
        width=256,
        height=256,
    )
    material = spec.add_material(name="floor")
    material.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "grid"
    material.texrepeat = [6, 6]
    world = spec.worldbody
    world.add_light(
        name="top",
        pos=[x, y, floor_z + 3.0],
        dir=[0.0, 0.0, -1.0],
        type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
    )
    world.add_geom(
        name="floor",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[4.0, 4.0, 0.05],
        pos=[x, y, floor_z],
        material="floor",
    )
    if table:
        # From a little behind the base to most of the reach in front, as wide as the reach both sides.
        back, front, half_width = 0.25, max(0.6, 0.9 * reach), max(0.5, 0.8 * reach)
        top = spec.worldbody.add_body(name="table", pos=[x + (front - back) / 2.0, y, z - TABLE_HEIGHT / 2.0])
        top.add_geom(
            name="table",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[(front + back) / 2.0, half_width, TABLE_HEIGHT / 2.0],
            rgba=[0.76, 0.7, 0.6, 1.0],
        )
        # The base is bolted to the table: every link fixed to the root may touch it.
        for link in mounted:
            spec.add_exclude(bodyname1="table", bodyname2=link)
    # In front, a little to the side (depth reads better than straight on), looking at the workspace.
    target = stand + np.array([0.3 * reach, 0.0, 0.2 * reach])
    position = stand + np.array([1.6 * reach + 0.4, 0.35 * reach, 0.9 * reach + 0.3])
    # As in lab_sim: the camera sits in an optical-frame body, which the driver stamps its images with.
    frame = world.add_body(
        name="scene_camera_optical_frame", pos=list(position), quat=_optical_frame_quat(position, target)
    )
    frame.add_camera(name="scene_camera", quat=[0.0, 1.0, 0.0, 0.0], fovy=55.0, resolution=[640, 480])
