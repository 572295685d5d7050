"""Write ``lab_sim.urdf`` and ``lab_sim_scene.xml`` from one table of links (the single source of truth).

The robot (a UR5e-sized arm on a linear rail with a parallel two-finger gripper) is described once, below,
as links with their joint, origin and primitive collision geoms. This script renders that table twice:
as URDF (for planning with pinocchio) and as the robot part of the MuJoCo scene, which also holds the lab
table, the tray, the object to pick, actuators and keyframes. The two cameras' optical frames are links
of the table too (the wrist camera's on tool0, the scene camera's on the world), so the frame tree knows
them; the MuJoCo ``<camera>`` elements sit in those links' bodies. Run it after editing the table::

    python configs/lab_sim/description/generate.py

``tests/sim/model`` checks that the two files agree (forward kinematics to 1e-6, identical collision
geoms) and that the committed files are what this script writes.

Conventions: SI units. The world frame is MoveIt Pro's lab_sim's: z up, the rail along world x, the table
toward +y, its top at z = 0.474 (MoveIt Pro's desk height; the floor is below z = 0). The cell is placed in
it by one rigid transform, :data:`CELL_YAW` and :data:`CELL_ORIGIN` (the rail base link's pose), so joint
values mean the same as before the cell was placed. Within the robot every link frame is aligned with
``linear_rail_base_link`` when all joints are zero (so joint origins are pure translations) except
``tool0`` and the gripper below it, whose z axis points out of the flange.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).resolve().parent

# Gripper: the knuckle angle (0 open .. 0.7929 closed, Robotiq 2F-85 convention) drives both finger
# slides through a linear coupling, each finger travelling 42.5 mm so the 85 mm stroke closes fully.
KNUCKLE_CLOSED = 0.7929
FINGER_TRAVEL = 0.0425
FINGER_PER_KNUCKLE = FINGER_TRAVEL / KNUCKLE_CLOSED
FINGER_HALF_THICKNESS = 0.01
TCP_DEPTH = 0.13  # grasp_link along the gripper z axis, from tool0
# The wrist force/torque sensor, between the flange and the gripper, as in MoveIt Pro's lab_sim: a site
# named like the ros2_control sensor (tcp_fts_sensor) carrying MuJoCo force and torque sensors. It sits at
# tool0, so its readings are in tool0's frame, the frame the force/torque broadcaster publishes them in.
FTS_LINK = "tool0"
FTS_SITE = "tcp_fts_sensor"

# The cell in the world: MoveIt Pro's lab_sim runs its rail along world x (rail joint + toward -x) with the
# work surface at +y, 0.474 m up. The cell (rail pedestal, table, tray, cube, scene camera) is built 0.75 m
# tall from the floor and turned a quarter turn about z, so the rail base frame's y axis is world -x.
TABLE_TOP = 0.474
TABLE_HEIGHT = 0.75  # floor to table top
FLOOR = TABLE_TOP - TABLE_HEIGHT
CELL_YAW = math.pi / 2
CELL_QUAT = (math.cos(CELL_YAW / 2), 0.0, 0.0, math.sin(CELL_YAW / 2))  # w x y z
CELL_ORIGIN = (0.0, 0.0, FLOOR)  # linear_rail_base_link in the world
TABLE_CENTER = (0.0, 0.7)  # the table: 2.4 m along the rail, 0.7 m deep, from y = 0.35 to 1.05
TABLE_HALF = (1.2, 0.35)
CUBE_HALF = 0.025
CUBE_START = (-0.30, 0.62, TABLE_TOP + CUBE_HALF)
TRAY_CENTER = (0.30, 0.62)
TRAY_FLOOR = 0.004  # thickness of the tray bottom: thin, so placing and re-picking stay level
# Inside the tray's walls, half extents along world x and y (the tray turns with the cell: world x is
# its local -y, world y its local x). Walls are 0.01 m thick and 0.04 m tall.
TRAY_INNER_HALF = (0.14, 0.17)
TRAY_WALL = 0.005  # half thickness

# MoveIt Pro's "Move Flasks to Burners" picks two flasks by their necks at its waypoints "Flask 1 - Pick" and
# "Flask 2 - Pick" and lowers each onto a burner below "Flask 1 - Place" / "Flask 2 - Place" until it touches.
# Each flask stands where its pick waypoint holds grasp_link (MoveIt Pro's world poses: the waypoints'
# joint values through MoveIt Pro's lab_sim URDF), each burner under its place waypoint. (MoveIt Pro's
# own desk.xml has moved its flasks since those waypoints were saved; the waypoints are what the objective
# uses.) The flasks are 250 ml Erlenmeyers made of three cylinders (base, shoulder, neck; MoveIt Pro's
# collision neck is 14 mm in radius), free to be picked; the burners are fixed hot plates.
FLASK_PARTS = (  # name, radius, z from, z to (m above the flask's base), mass (kg)
    ("base", 0.035, 0.0, 0.035, 0.08),
    ("shoulder", 0.025, 0.035, 0.055, 0.025),
    ("neck", 0.014, 0.04, 0.12, 0.015),
)
FLASKS = (("flask_1", (-0.357, 0.40)), ("flask_2", (-0.502, 0.474)))
BURNER_RADIUS = 0.045
BURNER_HEIGHT = 0.06
BURNERS = (("burner_1", (0.555, 0.56)), ("burner_2", (0.66, 0.56)))

# Cameras, named as MoveIt Pro's lab_sim names them (topics /<name>/color, depth, camera_info, points).
# Each sits in a link of its own whose frame follows the ROS optical convention (z forward, x right,
# y down), so that link is the frame_id of the camera's images and clouds and the frame tree knows it.
# MuJoCo cameras look along their -z with y up: the camera inside the link is turned half a turn about x.
CAMERA_IN_OPTICAL = (0.0, 1.0, 0.0, 0.0)  # w x y z
CAMERA_RESOLUTION = (640, 480)


@dataclass(frozen=True)
class Camera:
    """A camera: its optical-frame link (in :data:`LINKS`) and its vertical field of view, degrees."""

    name: str
    link: str
    fovy: float


CAMERAS = (
    Camera("scene_camera", "scene_camera_optical_frame", 55.0),
    Camera("wrist_camera", "wrist_camera_optical_frame", 58.0),
)


@dataclass(frozen=True)
class Geom:
    """A collision primitive in its link's frame.

    ``kind`` is ``box`` (``size`` = half extents, centred at ``pos``), ``cylinder`` (``fromto`` segment and
    ``size[0]`` = radius) or ``sphere`` (``size[0]`` = radius at ``pos``).
    """

    name: str
    kind: str
    size: tuple[float, ...]
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    fromto: tuple[float, ...] = ()
    rgba: str = "0.55 0.6 0.65 1"
    contact: str = ""  # extra MJCF contact attributes (finger pads)


@dataclass(frozen=True)
class Link:
    """A robot link, the joint that moves it (relative to ``parent``) and its geoms."""

    name: str
    parent: str
    joint: str | None = None  # None: fixed to the parent
    kind: str = "fixed"  # fixed, revolute, prismatic
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)  # w x y z
    limits: tuple[float, float] = (0.0, 0.0)
    effort: float = 0.0
    velocity: float = 0.0
    mass: float = 0.0
    geoms: tuple[Geom, ...] = field(default_factory=tuple)


ARM = "0.55 0.6 0.65 1"
DARK = "0.15 0.15 0.17 1"
ACCENT = "0.1 0.45 0.8 1"
PAD = 'friction="1.5 0.02 0.0005" condim="4" solref="0.004 1" solmix="1000" solimp="0.95 0.99 0.001"'
R_TOOL = (math.sqrt(0.5), -math.sqrt(0.5), 0.0, 0.0)  # Rx(-pi/2): tool0 z = wrist_3 y


def _quat_from_axes(
    x: tuple[float, float, float], z: tuple[float, float, float]
) -> tuple[float, float, float, float]:
    """The rotation (w x y z) whose x and z axes point along ``x`` and ``z`` (made orthonormal)."""
    zn = math.sqrt(sum(c * c for c in z))
    z = (z[0] / zn, z[1] / zn, z[2] / zn)
    dot = sum(a * b for a, b in zip(x, z, strict=True))
    x = (x[0] - dot * z[0], x[1] - dot * z[1], x[2] - dot * z[2])
    xn = math.sqrt(sum(c * c for c in x))
    x = (x[0] / xn, x[1] / xn, x[2] / xn)
    y = (z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0])
    m = ((x[0], y[0], z[0]), (x[1], y[1], z[1]), (x[2], y[2], z[2]))
    w = math.sqrt(max(0.0, 1.0 + m[0][0] + m[1][1] + m[2][2])) / 2
    qx = math.copysign(math.sqrt(max(0.0, 1.0 + m[0][0] - m[1][1] - m[2][2])) / 2, m[2][1] - m[1][2])
    qy = math.copysign(math.sqrt(max(0.0, 1.0 - m[0][0] + m[1][1] - m[2][2])) / 2, m[0][2] - m[2][0])
    qz = math.copysign(math.sqrt(max(0.0, 1.0 - m[0][0] - m[1][1] + m[2][2])) / 2, m[1][0] - m[0][1])
    return (w, qx, qy, qz)


Quat = tuple[float, float, float, float]


def _quat_mul(a: Quat, b: Quat) -> Quat:
    """The rotation ``a`` then ``b`` in ``a``'s frame (Hamilton product, w x y z)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    product = (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )
    return (round(product[0], 12), round(product[1], 12), round(product[2], 12), round(product[3], 12))


def _cell_to_world(xyz: tuple[float, float, float]) -> tuple[float, float, float]:
    """A point given in the rail base's frame (the cell as built), in the world."""
    c, s = math.cos(CELL_YAW), math.sin(CELL_YAW)
    x, y, z = xyz
    world = (c * x - s * y + CELL_ORIGIN[0], s * x + c * y + CELL_ORIGIN[1], z + CELL_ORIGIN[2])
    return (round(world[0], 12), round(world[1], 12), round(world[2], 12))  # no 1e-16 in the files


# The scene camera stands beyond the far edge of the table, 1.9 m above the floor, looking down across the
# table at the robot (given in the cell's frame: image x along the rail, image y mostly down).
SCENE_CAMERA_POS = _cell_to_world((2.1, 0.0, 1.9))
SCENE_CAMERA_QUAT = _quat_mul(CELL_QUAT, _quat_from_axes((0.0, 1.0, 0.0), (-1.6, 0.0, -1.05)))
# The wrist camera rides beside the gripper, 7.5 cm off the tool axis along tool0's x (clear of the
# fingers, which close along y) and level with the palm's face (so the palm stays out of the picture),
# looking out of the flange, tilted 15 degrees toward the tool axis: the fingertips show at the image's
# left edge and what lies between them in front.
WRIST_CAMERA_POS = (0.075, 0.0, 0.08)
WRIST_CAMERA_QUAT = (math.cos(-math.radians(15) / 2), 0.0, math.sin(-math.radians(15) / 2), 0.0)

LINKS: tuple[Link, ...] = (
    Link(
        "linear_rail_base_link",
        "world",
        xyz=CELL_ORIGIN,
        quat=CELL_QUAT,
        geoms=(Geom("rail_pedestal", "box", (0.12, 1.4, 0.36), pos=(0.0, 0.0, 0.36), rgba=DARK),),
    ),
    Link(
        "linear_rail_carriage_link",
        "linear_rail_base_link",
        "linear_rail_joint",
        "prismatic",
        axis=(0.0, 1.0, 0.0),
        xyz=(0.0, 0.0, 0.72),
        # +-1.2 m: MoveIt Pro's lab_sim trajectories (joint_trajectory.yaml) drive the rail to 1.175 m.
        limits=(-1.2, 1.2),
        effort=2000.0,
        velocity=1.0,
        mass=8.0,
        geoms=(Geom("rail_carriage", "box", (0.14, 0.14, 0.02), pos=(0.0, 0.0, 0.02), rgba=DARK),),
    ),
    Link(
        "base_link",
        "linear_rail_carriage_link",
        xyz=(0.0, 0.0, 0.04),
        mass=4.0,
        geoms=(Geom("base", "cylinder", (0.075,), fromto=(0.0, 0.0, 0.0, 0.0, 0.0, 0.09)),),
    ),
    Link(
        "shoulder_link",
        "base_link",
        "shoulder_pan_joint",
        "revolute",
        axis=(0.0, 0.0, 1.0),
        xyz=(0.0, 0.0, 0.1625),
        limits=(-math.pi, math.pi),
        effort=150.0,
        velocity=math.pi,
        mass=3.7,
        geoms=(
            Geom("shoulder_column", "cylinder", (0.06,), fromto=(0.0, 0.0, -0.07, 0.0, 0.0, 0.0)),
            Geom("shoulder_housing", "cylinder", (0.06,), fromto=(0.0, -0.06, 0.0, 0.0, 0.08, 0.0)),
        ),
    ),
    Link(
        "upper_arm_link",
        "shoulder_link",
        "shoulder_lift_joint",
        "revolute",
        axis=(0.0, 1.0, 0.0),
        xyz=(0.0, 0.138, 0.0),
        limits=(-math.pi, 0.0),
        effort=150.0,
        velocity=math.pi,
        mass=8.4,
        geoms=(
            Geom("upper_arm_housing", "cylinder", (0.06,), fromto=(0.0, -0.05, 0.0, 0.0, 0.06, 0.0)),
            Geom("upper_arm_tube", "cylinder", (0.045,), fromto=(0.06, 0.0, 0.0, 0.37, 0.0, 0.0)),
        ),
    ),
    Link(
        "forearm_link",
        "upper_arm_link",
        "elbow_joint",
        "revolute",
        axis=(0.0, 1.0, 0.0),
        xyz=(0.425, -0.131, 0.0),
        limits=(-math.pi, math.pi),
        effort=150.0,
        velocity=math.pi,
        mass=2.3,
        geoms=(
            Geom("elbow_housing", "cylinder", (0.05,), fromto=(0.0, -0.05, 0.0, 0.0, 0.17, 0.0)),
            Geom("forearm_tube", "cylinder", (0.038,), fromto=(0.05, 0.0, 0.0, 0.35, 0.0, 0.0)),
        ),
    ),
    Link(
        "wrist_1_link",
        "forearm_link",
        "wrist_1_joint",
        "revolute",
        axis=(0.0, 1.0, 0.0),
        xyz=(0.3922, 0.0, 0.0),
        limits=(-math.pi, math.pi),
        effort=28.0,
        velocity=math.pi,
        mass=1.2,
        geoms=(Geom("wrist_1_housing", "cylinder", (0.04,), fromto=(0.0, -0.04, 0.0, 0.0, 0.09, 0.0)),),
    ),
    Link(
        "wrist_2_link",
        "wrist_1_link",
        "wrist_2_joint",
        "revolute",
        axis=(0.0, 0.0, -1.0),
        xyz=(0.0, 0.1263, 0.0),
        limits=(-math.pi, math.pi),
        effort=28.0,
        velocity=math.pi,
        mass=1.2,
        geoms=(Geom("wrist_2_housing", "cylinder", (0.04,), fromto=(0.0, 0.0, 0.04, 0.0, 0.0, -0.06)),),
    ),
    Link(
        "wrist_3_link",
        "wrist_2_link",
        "wrist_3_joint",
        "revolute",
        axis=(0.0, 1.0, 0.0),
        xyz=(0.0, 0.0, -0.0997),
        limits=(-math.pi, math.pi),
        effort=28.0,
        velocity=math.pi,
        mass=0.25,
        geoms=(Geom("wrist_3_flange", "cylinder", (0.04,), fromto=(0.0, -0.04, 0.0, 0.0, 0.0996, 0.0)),),
    ),
    Link("tool0", "wrist_3_link", xyz=(0.0, 0.0996, 0.0), quat=R_TOOL),
    Link(
        "robotiq_85_base_link",
        "tool0",
        mass=0.6,
        geoms=(
            Geom("gripper_coupling", "cylinder", (0.04,), fromto=(0.0, 0.0, 0.0, 0.0, 0.0, 0.03), rgba=DARK),
            Geom("gripper_palm", "box", (0.03, 0.07, 0.025), pos=(0.0, 0.0, 0.055), rgba=DARK),
        ),
    ),
    Link(
        "robotiq_85_left_knuckle_link",
        "robotiq_85_base_link",
        "robotiq_85_left_knuckle_joint",
        "revolute",
        axis=(1.0, 0.0, 0.0),
        xyz=(0.0, 0.03, 0.06),
        limits=(0.0, KNUCKLE_CLOSED),
        effort=10.0,
        velocity=2.0,
        mass=0.02,
    ),
    Link(
        "robotiq_85_left_finger_link",
        "robotiq_85_base_link",
        "robotiq_85_left_finger_joint",
        "prismatic",
        axis=(0.0, -1.0, 0.0),
        xyz=(0.0, FINGER_TRAVEL + FINGER_HALF_THICKNESS, TCP_DEPTH - 0.015),
        limits=(0.0, FINGER_TRAVEL),
        effort=100.0,
        velocity=0.2,
        mass=0.05,
        geoms=(
            Geom("left_finger_pad", "box", (0.011, FINGER_HALF_THICKNESS, 0.035), rgba=ACCENT, contact=PAD),
        ),
    ),
    Link(
        "robotiq_85_right_finger_link",
        "robotiq_85_base_link",
        "robotiq_85_right_finger_joint",
        "prismatic",
        axis=(0.0, 1.0, 0.0),
        xyz=(0.0, -(FINGER_TRAVEL + FINGER_HALF_THICKNESS), TCP_DEPTH - 0.015),
        limits=(0.0, FINGER_TRAVEL),
        effort=100.0,
        velocity=0.2,
        mass=0.05,
        geoms=(
            Geom("right_finger_pad", "box", (0.011, FINGER_HALF_THICKNESS, 0.035), rgba=ACCENT, contact=PAD),
        ),
    ),
    Link("grasp_link", "robotiq_85_base_link", xyz=(0.0, 0.0, TCP_DEPTH)),
    # MoveIt Pro's lab_sim calls the point between the fingertips "pinch" too.
    Link("pinch", "grasp_link"),
    # Sites and bodies of MoveIt Pro's lab_sim MuJoCo model that its MPC objectives name (the flange's
    # attachment_site and tool_changer, the arm's base_site), as frames at the same places.
    Link("attachment_site", "tool0"),
    Link("tool_changer", "tool0"),
    Link("base_site", "base_link"),
    Link("wrist_camera_optical_frame", "tool0", xyz=WRIST_CAMERA_POS, quat=WRIST_CAMERA_QUAT),
    Link("scene_camera_optical_frame", "world", xyz=SCENE_CAMERA_POS, quat=SCENE_CAMERA_QUAT),
)

MIMIC = {
    "robotiq_85_left_finger_joint": ("robotiq_85_left_knuckle_joint", FINGER_PER_KNUCKLE),
    "robotiq_85_right_finger_joint": ("robotiq_85_left_knuckle_joint", FINGER_PER_KNUCKLE),
}

# name: (kp, kv, force limit) of the position servo on each actuated joint. The gripper servo saturates at
# 3 (tendon units: N·m per knuckle radian), i.e. about 28 N of squeeze per finger, whatever the object width.
SERVOS = {
    "linear_rail_joint": (20000.0, 1500.0, 2000.0),
    "shoulder_pan_joint": (2000.0, 150.0, 150.0),
    "shoulder_lift_joint": (2000.0, 150.0, 150.0),
    "elbow_joint": (1500.0, 100.0, 150.0),
    "wrist_1_joint": (300.0, 15.0, 28.0),
    "wrist_2_joint": (300.0, 15.0, 28.0),
    "wrist_3_joint": (300.0, 15.0, 28.0),
    "robotiq_85_left_knuckle_joint": (20.0, 0.5, 3.0),
}

GRIPPER_JOINT = "robotiq_85_left_knuckle_joint"
ARM_JOINTS = (
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
# The "Home" waypoint: arm folded above the rail, tool pointing down, gripper open.
HOME = (0.0, 0.0, -2.0, 2.0, -1.5708, -1.5708, 0.0)


def _f(x: float) -> str:
    text = f"{x:.10g}"
    return "0" if text == "-0" else text


def _vec(v: tuple[float, ...] | list[float]) -> str:
    return " ".join(_f(x) for x in v)


def _quat_to_rpy(q: tuple[float, float, float, float]) -> tuple[float, float, float]:
    w, x, y, z = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


def _cylinder_origin(fromto: tuple[float, ...]) -> tuple[tuple[float, ...], tuple[float, ...], float]:
    """Centre, URDF rpy and length of a cylinder given by its end points (URDF cylinders run along z)."""
    p1, p2 = fromto[:3], fromto[3:]
    centre = tuple((a + b) / 2 for a, b in zip(p1, p2, strict=True))
    d = [b - a for a, b in zip(p1, p2, strict=True)]
    length = math.sqrt(sum(c * c for c in d))
    ux, uy, uz = (c / length for c in d)
    # Rotation taking z to u: roll about x then pitch about y (rpy convention R = Rz Ry Rx).
    roll = math.atan2(-uy, math.hypot(ux, uz))
    pitch = math.atan2(ux, uz)
    return centre, (roll, pitch, 0.0), length


def _urdf_geometry(g: Geom) -> tuple[str, str]:
    if g.kind == "box":
        return f'<box size="{_vec([2 * s for s in g.size])}"/>', f'xyz="{_vec(g.pos)}" rpy="0 0 0"'
    if g.kind == "sphere":
        return f'<sphere radius="{_f(g.size[0])}"/>', f'xyz="{_vec(g.pos)}" rpy="0 0 0"'
    centre, rpy, length = _cylinder_origin(g.fromto)
    return (
        f'<cylinder radius="{_f(g.size[0])}" length="{_f(length)}"/>',
        f'xyz="{_vec(centre)}" rpy="{_vec(rpy)}"',
    )


def render_urdf() -> str:
    """Return the URDF of the robot (a ``world`` root link, as MoveIt Pro requires)."""
    out = [
        '<?xml version="1.0"?>',
        "<!-- Generated by generate.py from its link table; edit that, not this file. -->",
        '<robot name="lab_sim">',
        '  <link name="world"/>',
    ]
    for link in LINKS:
        out.append(f'  <link name="{link.name}">')
        if link.mass > 0:
            i = 0.01 * link.mass
            out.append(
                f'    <inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="{_f(link.mass)}"/>'
                f'<inertia ixx="{_f(i)}" ixy="0" ixz="0" iyy="{_f(i)}" iyz="0" izz="{_f(i)}"/></inertial>'
            )
        for g in link.geoms:
            shape, origin = _urdf_geometry(g)
            out.append(f'    <visual name="{g.name}"><origin {origin}/><geometry>{shape}</geometry></visual>')
            out.append(
                f'    <collision name="{g.name}"><origin {origin}/><geometry>{shape}</geometry></collision>'
            )
        out.append("  </link>")
        jname = link.joint or f"{link.parent}_to_{link.name}"
        out.append(f'  <joint name="{jname}" type="{link.kind}">')
        out.append(f'    <parent link="{link.parent}"/><child link="{link.name}"/>')
        out.append(f'    <origin xyz="{_vec(link.xyz)}" rpy="{_vec(_quat_to_rpy(link.quat))}"/>')
        if link.kind != "fixed":
            out.append(f'    <axis xyz="{_vec(link.axis)}"/>')
            lo, hi = link.limits
            out.append(
                f'    <limit lower="{_f(lo)}" upper="{_f(hi)}" effort="{_f(link.effort)}" '
                f'velocity="{_f(link.velocity)}"/>'
            )
        if link.joint in MIMIC:
            leader, ratio = MIMIC[link.joint]
            out.append(f'    <mimic joint="{leader}" multiplier="{_f(ratio)}" offset="0"/>')
        out.append("  </joint>")
    out.append("</robot>")
    return "\n".join(out) + "\n"


def _mjcf_geom(g: Geom, indent: str) -> str:
    common = f'name="{g.name}" rgba="{g.rgba}"' + (f" {g.contact}" if g.contact else "")
    if g.kind == "box":
        return f'{indent}<geom {common} type="box" size="{_vec(g.size)}" pos="{_vec(g.pos)}"/>'
    if g.kind == "sphere":
        return f'{indent}<geom {common} type="sphere" size="{_f(g.size[0])}" pos="{_vec(g.pos)}"/>'
    return f'{indent}<geom {common} type="cylinder" size="{_f(g.size[0])}" fromto="{_vec(g.fromto)}"/>'


def _mjcf_body(link: Link, depth: int) -> list[str]:
    ind = "  " * depth
    attrs = f'name="{link.name}" pos="{_vec(link.xyz)}"'
    if link.quat != (1.0, 0.0, 0.0, 0.0):
        attrs += f' quat="{_vec(link.quat)}"'
    if link.parent != "world":
        attrs += ' gravcomp="1"'
    out = [f"{ind}<body {attrs}>"]
    if link.kind != "fixed":
        jtype = "hinge" if link.kind == "revolute" else "slide"
        lo, hi = link.limits
        extra = ' armature="0.1" damping="1"' if link.kind == "revolute" else ' armature="0.1" damping="10"'
        if link.name.startswith("robotiq_85_left_knuckle"):
            extra = ' armature="0.0001" damping="0.001"'
        elif link.name.startswith("robotiq"):
            extra = ' armature="0.05" damping="0.5"'
        out.append(
            f'{ind}  <joint name="{link.joint}" type="{jtype}" axis="{_vec(link.axis)}" '
            f'range="{_f(lo)} {_f(hi)}"{extra}/>'
        )
    if link.mass > 0:
        i = 0.01 * link.mass
        out.append(
            f'{ind}  <inertial pos="0 0 0" mass="{_f(link.mass)}" diaginertia="{_f(i)} {_f(i)} {_f(i)}"/>'
        )
    if link.name == "robotiq_85_left_knuckle_link":
        out.append(
            f'{ind}  <geom name="left_knuckle" type="box" size="0.006 0.012 0.02" pos="0 0 0.02" '
            f'contype="0" conaffinity="0" group="1" mass="0" rgba="{DARK}"/>'
        )
    for g in link.geoms:
        out.append(_mjcf_geom(g, ind + "  "))
    if link.name == "grasp_link":
        out.append(f'{ind}  <site name="grasp_site" size="0.005" rgba="1 0 0 1"/>')
    if link.name == FTS_LINK:
        out.append(f'{ind}  <site name="{FTS_SITE}" size="0.01" rgba="0 1 0 0"/>')
    for camera in CAMERAS:
        if camera.link == link.name:
            out.append(
                f'{ind}  <camera name="{camera.name}" quat="{_vec(CAMERA_IN_OPTICAL)}" '
                f'fovy="{_f(camera.fovy)}" resolution="{_vec(CAMERA_RESOLUTION)}"/>'
            )
    for child in LINKS:
        if child.parent == link.name:
            out.extend(_mjcf_body(child, depth + 1))
    out.append(f"{ind}</body>")
    return out


# AprilTag-marked objects (MoveIt Pro's tag-pick objectives), in a file of their own that the scene
# <include>s: lab_sim_apriltags.xml. Those objectives look for tag36h11 tags whose black square is
# 28.8 mm on the objects (get_april_tag_pose_from_image.xml) and 64 mm, id 1, by the tray
# (pick_all_bottles_with_apriltags.xml). Each tag is a thin visual-only box on top of its object,
# textured with the tag's image as the AprilTag library draws it (textures/, 16 pixels a cell so the
# renderer's filtering keeps the edges sharp). A tag's frame is its box's top face: x along the tag's
# rows, y up its columns, z out of the face, the frame DetectAprilTags reports.
TAG_FAMILY = "tag36h11"
TAG_CELLS = 10  # a tag36h11 image with its white margin; the black square is the middle 8 cells
TAG_THICKNESS = 0.001
TAG_TEXTURE_SCALE = 16
OBJECT_TAG_SIZE = 0.0288
TRAY_TAG_SIZE = 0.064
TRAY_TAG_ID = 1
APRILTAGS_FILE = "lab_sim_apriltags.xml"


@dataclass(frozen=True)
class TaggedObject:
    """A box to pick with an AprilTag on its top face.

    Attributes:
        name: body (and geom) name; its free joint is ``<name>_joint``.
        tag_id: the tag36h11 id on top.
        half: half extents (x, y, z), m.
        start: centre of the box at rest on the table.
        yaw: turn about the world z, radians.
    """

    name: str
    tag_id: int
    half: tuple[float, float, float]
    start: tuple[float, float, float]
    yaw: float
    rgba: str = "0.2 0.35 0.75 1"
    mass: float = 0.05


TAG_BLOCK_HALF = (0.02, 0.02, 0.04)
TAGGED_OBJECTS = (
    TaggedObject(
        "tag_block",
        0,
        TAG_BLOCK_HALF,
        (0.0, 0.52, TABLE_TOP + TAG_BLOCK_HALF[2]),
        CELL_YAW + math.radians(20.0),
    ),
)
# The block stands where the wrist camera sees it from "Look at Table" at about 0.53 m (its tag about 40 px
# wide), 15 cm from where "Register CAD Part Subtree" guesses a bottle (-0.15, 0.5): nearer, ICP fitted the
# bottle model onto the block. The tray's tag lies on the tray's floor, TRAY_TAG_TO_CENTER (MoveIt Pro's
# tag_to_tray_center in pick_all_bottles_with_apriltags.xml) from the tray's centre toward the robot
# (world -y), unturned: its +y axis points at the tray's centre, the direction
# ComputeTrayPlacePositionsUsingAprilTags steps along. The bottle slots (3 rows 0.10 m apart along world x,
# 2 columns 0.09 m apart along world y) take the middle of the tray; the tray is deep enough along y
# (TRAY_INNER_HALF) for the tag beside them.
TRAY_TAG_TO_CENTER = 0.125
TRAY_TAG_CENTER = (TRAY_CENTER[0], TRAY_CENTER[1] - TRAY_TAG_TO_CENTER, TABLE_TOP + TRAY_FLOOR)


def _yaw_quat(yaw: float) -> tuple[float, float, float, float]:
    return (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


def tag_texture(tag_id: int) -> str:
    """The texture (and material) name of a tag."""
    return f"{TAG_FAMILY}_{tag_id:05d}"


def tag_texture_png(tag_id: int) -> bytes:
    """The PNG of a tag: the AprilTag library's bitmap, each cell :data:`TAG_TEXTURE_SCALE` pixels."""
    import io

    import numpy as np
    from PIL import Image

    from kinema.perception.apriltags import tag_image

    cells = tag_image(TAG_FAMILY, tag_id)
    pixels = np.kron(cells, np.ones((TAG_TEXTURE_SCALE, TAG_TEXTURE_SCALE), dtype=np.uint8))
    buffer = io.BytesIO()
    Image.fromarray(np.repeat(pixels[:, :, None], 3, axis=2)).save(buffer, format="PNG", optimize=False)
    return buffer.getvalue()


def _tag_geom(name: str, tag_id: int, tag_size: float, z: float, indent: str) -> str:
    half = tag_size * TAG_CELLS / (TAG_CELLS - 2) / 2
    return (
        f'{indent}<geom name="{name}" type="box" size="{_f(half)} {_f(half)} {_f(TAG_THICKNESS / 2)}" '
        f'pos="0 0 {_f(z + TAG_THICKNESS / 2)}" material="{tag_texture(tag_id)}" contype="0" '
        'conaffinity="0" mass="0"/>'
    )


def render_apriltags() -> str:
    """Return lab_sim_apriltags.xml: the tag textures, the tagged objects and the tray's tag."""
    ids = sorted({o.tag_id for o in TAGGED_OBJECTS} | {TRAY_TAG_ID})
    lines = [
        "<!-- Generated by generate.py (AprilTag-marked objects); edit that, not this file. -->",
        '<mujoco model="lab_sim apriltags">',
        "  <asset>",
        *(
            f'    <texture name="{tag_texture(i)}" type="2d" file="textures/{tag_texture(i)}.png"/>\n'
            f'    <material name="{tag_texture(i)}" texture="{tag_texture(i)}" specular="0" shininess="0"/>'
            for i in ids
        ),
        "  </asset>",
        "  <worldbody>",
    ]
    for o in TAGGED_OBJECTS:
        lines += [
            f'    <body name="{o.name}" pos="{_vec(o.start)}" quat="{_vec(_yaw_quat(o.yaw))}">',
            f'      <freejoint name="{o.name}_joint"/>',
            f'      <geom name="{o.name}" type="box" size="{_vec(o.half)}" mass="{_f(o.mass)}" '
            f'friction="1 0.01 0.0001" condim="4" rgba="{o.rgba}"/>',
            _tag_geom(f"{o.name}_apriltag", o.tag_id, OBJECT_TAG_SIZE, o.half[2], "      "),
            "    </body>",
        ]
    lines += [
        f'    <body name="tray_apriltag" pos="{_vec(TRAY_TAG_CENTER)}">',
        _tag_geom("tray_apriltag", TRAY_TAG_ID, TRAY_TAG_SIZE, 0.0, "      "),
        "    </body>",
        "  </worldbody>",
        "</mujoco>",
    ]
    return "\n".join(lines) + "\n"


def _keyframe_qpos(arm: tuple[float, ...], knuckle: float) -> str:
    finger = knuckle * FINGER_PER_KNUCKLE
    cube = (*CUBE_START, 1.0, 0.0, 0.0, 0.0)
    flasks = [v for _name, (x, y) in FLASKS for v in (x, y, TABLE_TOP, 1.0, 0.0, 0.0, 0.0)]
    tagged = [v for o in TAGGED_OBJECTS for v in (*o.start, *_yaw_quat(o.yaw))]
    return _vec([*arm, knuckle, finger, finger, *cube, *flasks, *tagged])


def _flask_and_burner_bodies() -> list[str]:
    """The flasks (free, origin at the centre of the base) and the burners (fixed) on the table."""
    lines = []
    for name, (x, y) in FLASKS:
        lines += [
            f'    <body name="{name}" pos="{_f(x)} {_f(y)} {_f(TABLE_TOP)}">',
            f'      <freejoint name="{name}_joint"/>',
        ]
        for part, radius, low, high, mass in FLASK_PARTS:
            size = f"{_f(radius)} {_f((high - low) / 2)}"
            lines.append(
                f'      <geom name="{name}_{part}" type="cylinder" size="{size}" '
                f'pos="0 0 {_f((low + high) / 2)}" mass="{_f(mass)}" friction="1 0.01 0.0001" condim="4" '
                'rgba="0.75 0.88 0.92 0.6"/>'
            )
        lines.append("    </body>")
    for name, (x, y) in BURNERS:
        lines += [
            f'    <body name="{name}" pos="{_f(x)} {_f(y)} {_f(TABLE_TOP)}">',
            f'      <geom name="{name}" type="cylinder" size="{_f(BURNER_RADIUS)} {_f(BURNER_HEIGHT / 2)}" '
            f'pos="0 0 {_f(BURNER_HEIGHT / 2)}" rgba="0.25 0.25 0.27 1"/>',
            # The hot plate on top: drawn only, steel grey (red in a camera image is the cube alone).
            f'      <geom name="{name}_ring" type="cylinder" size="{_f(BURNER_RADIUS - 0.01)} 0.001" '
            f'pos="0 0 {_f(BURNER_HEIGHT + 0.001)}" rgba="0.6 0.6 0.63 1" contype="0" conaffinity="0"/>',
            "    </body>",
        ]
    return lines


def render_scene() -> str:
    """Return the MuJoCo scene: robot and cameras from the link table, table, tray, cube, actuators."""
    tx, ty = TRAY_CENTER
    ix, iy = TRAY_INNER_HALF
    w = TRAY_WALL
    robot = []
    for link in LINKS:
        if link.parent == "world":
            robot.extend(_mjcf_body(link, 2))
    actuators = []
    for joint, (kp, kv, force) in SERVOS.items():
        lo, hi = next(link.limits for link in LINKS if link.joint == joint)
        target = 'tendon="robotiq_85_grip"' if joint == GRIPPER_JOINT else f'joint="{joint}"'
        actuators.append(
            f'    <position name="{joint}" {target} kp="{_f(kp)}" kv="{_f(kv)}" '
            f'ctrlrange="{_f(lo)} {_f(hi)}" forcerange="{_f(-force)} {_f(force)}"/>'
        )
    ctrl = _vec([*HOME, 0.0])
    home_qpos = _keyframe_qpos(HOME, 0.0)
    lines = [
        "<!-- Generated by generate.py from its link table; edit that, not this file. -->",
        '<mujoco model="lab_sim">',
        '  <compiler angle="radian" autolimits="true"/>',
        '  <option timestep="0.002" integrator="implicitfast" cone="elliptic" impratio="10"/>',
        "  <visual>",
        f'    <global offwidth="{CAMERA_RESOLUTION[0]}" offheight="{CAMERA_RESOLUTION[1]}"/>',
        '    <quality shadowsize="2048"/>',
        "  </visual>",
        "  <asset>",
        '    <texture name="sky" type="skybox" builtin="gradient" rgb1="0.75 0.8 0.85" rgb2="0.35 0.4 0.45" '
        'width="128" height="128"/>',
        '    <texture name="grid" type="2d" builtin="checker" rgb1="0.82 0.82 0.84" rgb2="0.74 0.74 0.76" '
        'width="256" height="256"/>',
        '    <material name="floor" texture="grid" texrepeat="6 6"/>',
        "  </asset>",
        "  <worldbody>",
        f'    <light name="top" pos="0 0.5 {_f(FLOOR + 3)}" dir="0 0 -1" directional="true"/>',
        f'    <geom name="floor" type="plane" size="4 4 0.05" pos="0 0 {_f(FLOOR)}" material="floor"/>',
        f'    <geom name="table" type="box" size="{_vec([*TABLE_HALF, TABLE_HEIGHT / 2])}" '
        f'pos="{_vec([*TABLE_CENTER, FLOOR + TABLE_HEIGHT / 2])}" rgba="0.76 0.7 0.6 1"/>',
        *robot,
        # The tray turns with the cell: its walls are given in the rail base's axes.
        f'    <body name="tray" pos="{_f(tx)} {_f(ty)} {_f(TABLE_TOP)}" quat="{_vec(CELL_QUAT)}">',
        f'      <geom name="tray_floor" type="box" size="{_f(iy)} {_f(ix)} {_f(TRAY_FLOOR / 2)}" '
        f'pos="0 0 {_f(TRAY_FLOOR / 2)}" rgba="0.3 0.5 0.35 1"/>',
        f'      <geom name="tray_wall_front" type="box" size="{_f(iy + w)} {_f(w)} 0.02" '
        f'pos="0 {_f(ix + w)} 0.02" rgba="0.3 0.5 0.35 1"/>',
        f'      <geom name="tray_wall_back" type="box" size="{_f(iy + w)} {_f(w)} 0.02" '
        f'pos="0 {_f(-ix - w)} 0.02" rgba="0.3 0.5 0.35 1"/>',
        f'      <geom name="tray_wall_left" type="box" size="{_f(w)} {_f(ix)} 0.02" '
        f'pos="{_f(iy + w)} 0 0.02" rgba="0.3 0.5 0.35 1"/>',
        f'      <geom name="tray_wall_right" type="box" size="{_f(w)} {_f(ix)} 0.02" '
        f'pos="{_f(-iy - w)} 0 0.02" rgba="0.3 0.5 0.35 1"/>',
        "    </body>",
        f'    <body name="cube" pos="{_vec(CUBE_START)}">',
        '      <freejoint name="cube_joint"/>',
        f'      <geom name="cube" type="box" size="{_vec([CUBE_HALF] * 3)}" mass="0.08" '
        'friction="1 0.01 0.0001" condim="4" rgba="0.85 0.2 0.2 1"/>',
        "    </body>",
        *_flask_and_burner_bodies(),
        # The bottles and microscope the point-cloud objectives look at (perception_objects.py).
        '    <include file="lab_sim_perception_objects.xml"/>',
        "  </worldbody>",
        f'  <include file="{APRILTAGS_FILE}"/>',
        "  <contact>",
        # The rail base is welded to the world, so MuJoCo's parent filter does not cover its children.
        '    <exclude body1="linear_rail_base_link" body2="linear_rail_carriage_link"/>',
        '    <exclude body1="linear_rail_base_link" body2="base_link"/>',
        '    <exclude body1="robotiq_85_left_finger_link" body2="robotiq_85_right_finger_link"/>',
        "  </contact>",
        "  <tendon>",
        # The gripper servo acts on the fingers through this tendon, whose length is the knuckle angle the
        # fingers' opening corresponds to: its ctrl is MoveIt Pro's gripper position (0 open, 0.7929 closed).
        '    <fixed name="robotiq_85_grip">',
        f'      <joint joint="robotiq_85_left_finger_joint" coef="{_f(0.5 / FINGER_PER_KNUCKLE)}"/>',
        f'      <joint joint="robotiq_85_right_finger_joint" coef="{_f(0.5 / FINGER_PER_KNUCKLE)}"/>',
        "    </fixed>",
        "  </tendon>",
        "  <equality>",
        # The fingers move together; the knuckle (a light visual link) follows them, so the knuckle joint
        # reports the real opening and no grip force has to flow through a soft coupling. Both couplings
        # are stiff: with the default solref the light knuckle rings for ~100 ms after the arm stops,
        # which /joint_states would report as gripper motion.
        '    <joint name="finger_coupling" joint1="robotiq_85_right_finger_joint" '
        'joint2="robotiq_85_left_finger_joint" solref="0.004 1"/>',
        f'    <joint name="knuckle_follows_fingers" joint1="robotiq_85_left_knuckle_joint" '
        f'joint2="robotiq_85_left_finger_joint" polycoef="0 {_f(1 / FINGER_PER_KNUCKLE)} 0 0 0" '
        'solref="0.004 1"/>',
        "  </equality>",
        "  <actuator>",
        *actuators,
        "  </actuator>",
        "  <sensor>",
        f'    <force name="{FTS_SITE}_force" site="{FTS_SITE}"/>',
        f'    <torque name="{FTS_SITE}_torque" site="{FTS_SITE}"/>',
        "  </sensor>",
        "  <keyframe>",
        f'    <key name="default" qpos="{home_qpos}" ctrl="{ctrl}"/>',
        f'    <key name="home" qpos="{home_qpos}" ctrl="{ctrl}"/>',
        "  </keyframe>",
        "</mujoco>",
    ]
    return "\n".join(lines) + "\n"


def main() -> None:
    """Write the URDF, the scene, its AprilTag include and the tag textures next to this script."""
    (HERE / "lab_sim.urdf").write_text(render_urdf())
    (HERE / "lab_sim_scene.xml").write_text(render_scene())
    (HERE / APRILTAGS_FILE).write_text(render_apriltags())
    (HERE / "textures").mkdir(exist_ok=True)
    for tag_id in sorted({o.tag_id for o in TAGGED_OBJECTS} | {TRAY_TAG_ID}):
        (HERE / "textures" / f"{tag_texture(tag_id)}.png").write_bytes(tag_texture_png(tag_id))


if __name__ == "__main__":
    main()
