"""``kinema build``'s robot linter: every name that crosses a file of the robot is checked once.

A config's robot is spread over files written by different people and tools: the URDF (or xacro) names
joints and links, the SRDF groups them, joint_limits.yaml, the waypoints and the controllers name joints,
the MuJoCo scene must simulate and actuate them, config.yaml names a planning group, a tool frame, a
keyframe and a sensor site. A misspelt name in any of them fails late (when an objective runs) and far
from its cause. :func:`check_robot` reads them all and reports every problem at once, each naming the
file (and line where known) and the names that would have been valid:

- the URDF: xacro expands with the config's ``urdf_params``, every mesh is found and is not a Git LFS
  pointer, pinocchio loads it and its collision model builds;
- the SRDF: each group's joints, links and chains are the URDF's, subgroups are groups, the planning
  group (``moveit_params.joint_group_name``) is a group, group states and end effectors name URDF joints,
  groups and links;
- joint_limits.yaml names URDF joints;
- the MuJoCo scene: every file it and its includes name (include, mesh, texture, hfield, skin) exists and
  is not an LFS pointer, and no mesh is a text STL (MuJoCo reads binary STL only) — checked before MuJoCo
  parses it, so the message is Kinema's — then it loads, simulates every active URDF joint (movable, not
  a mimic) and has the configured keyframe;
- the waypoints name URDF joints;
- the controllers' and the gripper's joints are URDF joints actuated in the scene (by an actuator named
  like the joint, as the MuJoCo driver finds them), the tool frame is a URDF link, the F/T sensor's sites
  are in the scene.

Where an ``<include>`` or an asset of the scene is looked for is :mod:`kinema.config.mujoco_scene`'s rule,
the one the simulation driver and ``kinema view`` load the scene by.

A later check that needs an earlier one's result is skipped when that failed (no SRDF check without a
URDF), so one mistake is reported once.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from lxml import etree

from kinema.config.mujoco_scene import SceneFiles, asset_folders
from kinema.errors import ConfigError, KinemaError, MotionError, SourceLocation, did_you_mean

if TYPE_CHECKING:
    from kinema.config.inheritance import ResolvedConfig
    from kinema.config.robot_files import PackageIndex
    from kinema.motion.srdf import SemanticDescription


@dataclass
class RobotReport:
    """What :func:`robot_report` found.

    Attributes:
        problems: errors a build fails on, each with ``file:line`` where known.
        warnings: worth saying, not wrong (an SRDF disabling collisions of a link the URDF lacks).
        checked: the files that were read, for a summary.
    """

    problems: list[ConfigError] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    checked: list[Path] = field(default_factory=list)

    def problem(self, message: str, location: SourceLocation | str | Path | None = None) -> None:
        if location is not None and not isinstance(location, SourceLocation):
            location = SourceLocation(str(location))
        self.problems.append(ConfigError(message, location=location))


@dataclass(frozen=True)
class _Urdf:
    """The names the URDF defines."""

    source: Path
    joints: dict[str, Any]  # name -> kinema.config.robot_files.UrdfJoint
    links: list[str]
    # The collision checker of the robot as the planner loads it (None when pinocchio could not): the
    # waypoint check reuses it rather than loading the meshes again.
    checker: Any = None

    @property
    def movable_joints(self) -> list[str]:
        """The joints a waypoint, a limit or a controller can name: revolute, continuous, prismatic."""
        return [j.name for j in self.joints.values() if j.movable]

    @property
    def active_joints(self) -> list[str]:
        return [j.name for j in self.joints.values() if j.movable and j.mimic is None]

    def describe(self, what: str) -> str:
        return f"{what} of {self.source.name}"


def check_robot(resolved: ResolvedConfig) -> list[ConfigError]:
    """Every problem of the config's robot files (see the module docstring); empty when all fit."""
    return robot_report(resolved).problems


def robot_report(resolved: ResolvedConfig) -> RobotReport:
    """Check the config's robot files; problems and warnings, each naming file and line."""
    from kinema.config.robot_description import package_index

    report = RobotReport()
    index = package_index(resolved)
    urdf = _check_urdf(resolved, index, report)
    scene = _check_scene(resolved, urdf, report)
    if urdf is None:
        return report
    semantic = _check_srdf(resolved, urdf, report)
    _check_joint_limits(resolved, urdf, report)
    _check_waypoints(resolved, urdf, report)
    _check_cell(resolved, urdf, scene, report)
    if not report.problems and semantic is not None:
        # Each name is known: where the robot stands at each waypoint means something.
        _check_waypoint_collisions(resolved, urdf, semantic, scene, report)
    return report


def _attempt(report: RobotReport, action: Callable[[], Any]) -> Any:
    """``action()``, or None after recording its KinemaError as a problem."""
    try:
        return action()
    except KinemaError as error:
        report.problems.append(
            error if isinstance(error, ConfigError) else ConfigError(error.message, location=error.location)
        )
        return None


# -- URDF ------------------------------------------------------------------------------------------------


def _check_urdf(resolved: ResolvedConfig, index: PackageIndex, report: RobotReport) -> _Urdf | None:
    from kinema.config.robot_files import parse_joints, process_xacro, resolve_robot_text

    source = _attempt(report, lambda: resolved.urdf_path)
    if source is None:
        return None
    report.checked.append(source)
    text = _attempt(report, lambda: process_xacro(source, resolved.urdf_params, index=index))
    if text is None:
        return None
    try:
        root = etree.fromstring(text.encode("utf-8"))
    except etree.XMLSyntaxError as exc:
        report.problem(f"the URDF is not valid XML: {exc.msg}", SourceLocation(str(source), exc.lineno or 0))
        return None
    if root.tag != "robot":
        report.problem(f"not a URDF: the root element is <{root.tag}>, not <robot>", source)
        return None
    urdf = _Urdf(
        source=source,
        joints={j.name: j for j in parse_joints(text)},
        links=[link.get("name", "") for link in root.findall("link")],
    )
    if not urdf.active_joints:
        report.problem("the URDF has no movable joints (revolute, continuous or prismatic)", source)
    robot = _attempt(report, lambda: resolve_robot_text(source, text, index=index))
    if robot is not None:
        urdf = replace(urdf, checker=_check_pinocchio(resolved, index, report))
    return urdf


def _check_pinocchio(resolved: ResolvedConfig, index: PackageIndex, report: RobotReport) -> Any:
    """Pinocchio loads the URDF the planner loads, and its collision model builds; returns its collision
    checker (None when it does not load)."""
    from kinema.config.robot_description import planning_urdf
    from kinema.errors import MotionError
    from kinema.motion.collision import CollisionChecker
    from kinema.motion.robot_model import RobotModel

    path = _attempt(report, lambda: planning_urdf(resolved, check_meshes=False))
    if path is None:
        return None
    try:
        return CollisionChecker(RobotModel.from_urdf(path, package_dirs=index.package_dirs()))
    except MotionError as error:
        report.problem(error.message, error.location or resolved.urdf_path)
        return None


# -- SRDF ------------------------------------------------------------------------------------------------


def _check_srdf(resolved: ResolvedConfig, urdf: _Urdf, report: RobotReport) -> SemanticDescription | None:
    """Check the SRDF's names against the URDF; its semantic description when it reads."""
    path = _attempt(report, lambda: resolved.srdf_path)
    if path is None:
        return None
    report.checked.append(path)
    try:
        root = etree.parse(str(path)).getroot()
    except (OSError, etree.XMLSyntaxError) as exc:
        line = getattr(exc, "lineno", 0) or 0
        report.problem(f"the SRDF cannot be read: {exc}", SourceLocation(str(path), line))
        return None

    def where(element: etree._Element) -> SourceLocation:
        return SourceLocation(str(path), element.sourceline or 0)

    def name_check(element: etree._Element, attribute: str, valid: Iterable[str], what: str) -> bool:
        value = element.get(attribute, "")
        if value in valid:
            return True
        if not value.strip():
            return False  # an element without the attribute is skipped: its note says so (below)
        report.problem(
            f"<{element.tag} {attribute}={value!r}>: {value!r} is not a {what}; {did_you_mean(value, valid)}",
            where(element),
        )
        return False

    from kinema.errors import MotionError
    from kinema.motion.srdf import parse_srdf

    semantic: SemanticDescription | None = None
    try:
        semantic = parse_srdf(path)
        report.warnings.extend(semantic.notes)
    except MotionError as error:
        report.problem(error.message, error.location or path)
    joints, links = list(urdf.joints), urdf.links
    groups = {g.get("name", ""): g for g in root.findall("group")}
    parent_of = {j.child: j.parent for j in urdf.joints.values()}
    for group in groups.values():
        for element in group.findall("joint"):
            name_check(element, "name", joints, urdf.describe("joint"))
        for element in group.findall("link"):
            name_check(element, "name", links, urdf.describe("link"))
        for element in group.findall("group"):
            name_check(element, "name", groups, "group of the SRDF")
        for chain in group.findall("chain"):
            ends = [name_check(chain, end, links, urdf.describe("link")) for end in ("base_link", "tip_link")]
            base, tip = chain.get("base_link", ""), chain.get("tip_link", "")
            if all(ends) and not _is_below(tip, base, parent_of):
                report.problem(
                    f"group {group.get('name')!r}: the chain's tip {tip!r} is not below its base {base!r} in "
                    f"the URDF",
                    where(chain),
                )
    planning_group = resolved.get("moveit_params.joint_group_name")
    if planning_group and str(planning_group) not in groups:
        report.problem(
            f"the planning group {planning_group!r} (moveit_params.joint_group_name) is not a group of the "
            f"SRDF {path}; {did_you_mean(str(planning_group), groups)}",
            resolved.location_of("moveit_params.joint_group_name"),
        )
    for state in root.findall("group_state"):
        name_check(state, "group", groups, "group of the SRDF")
        for element in state.findall("joint"):
            name_check(element, "name", joints, urdf.describe("joint"))
    for effector in root.iter("end_effector"):
        name_check(effector, "parent_link", links, urdf.describe("link"))
        name_check(effector, "group", groups, "group of the SRDF")
        if effector.get("parent_group"):
            name_check(effector, "parent_group", groups, "group of the SRDF")
    for passive in root.iter("passive_joint"):
        name_check(passive, "name", joints, urdf.describe("joint"))
    known = set(links)
    for pair in root.iter("disable_collisions"):
        unknown = [pair.get(a, "") for a in ("link1", "link2") if pair.get(a, "") not in known]
        if unknown:  # MoveIt ignores such a pair with a warning; so does Kinema
            report.warnings.append(
                f"{where(pair)}: <disable_collisions> names {', '.join(map(repr, unknown))}, not a link of "
                f"{urdf.source.name}; the pair is ignored"
            )
    return semantic


def _is_below(tip: str, base: str, parent_of: Mapping[str, str]) -> bool:
    link, seen = tip, set()
    while link != base:
        if link not in parent_of or link in seen:
            return False
        seen.add(link)
        link = parent_of[link]
    return True


# -- joint limits and waypoints ----------------------------------------------------------------------------


def _check_joint_limits(resolved: ResolvedConfig, urdf: _Urdf, report: RobotReport) -> None:
    from kinema.config.yamlsource import load_yaml_file

    path = _attempt(report, lambda: resolved.joint_limits_path)
    if path is None:
        return
    report.checked.append(path)
    document = _attempt(report, lambda: load_yaml_file(path))
    if document is None:
        return
    limits = document.data.get("joint_limits") if isinstance(document.data, dict) else None
    if not isinstance(limits, dict):
        return
    for joint in limits:
        if str(joint) not in urdf.joints:
            report.problem(
                f"joint_limits names joint {joint!r}, which is not a {urdf.describe('joint')}; "
                f"{did_you_mean(str(joint), urdf.movable_joints)}",
                document.location(("joint_limits", joint)),
            )


def _check_waypoints(resolved: ResolvedConfig, urdf: _Urdf, report: RobotReport) -> None:
    from kinema.config.waypoints import Waypoint
    from kinema.config.yamlsource import load_yaml_file

    path = _attempt(report, lambda: resolved.waypoints_path)
    if path is None:
        return
    report.checked.append(path)
    document = _attempt(report, lambda: load_yaml_file(path))
    if document is None or not isinstance(document.data, list):
        return
    for number, item in enumerate(document.data):
        try:
            waypoint = Waypoint.from_dict(item, document, number)
        except ConfigError as error:
            report.problems.append(error)
            continue
        unknown = [j for j in waypoint.joint_names if j not in urdf.joints]
        if unknown:
            report.problem(
                f"waypoint {waypoint.name!r} names {_joints(unknown)} not in {urdf.source.name}; "
                f"{did_you_mean(unknown[0], urdf.movable_joints)}",
                document.location((number, "joint_state", "name")),
            )


def _check_waypoint_collisions(
    resolved: ResolvedConfig,
    urdf: _Urdf,
    semantic: SemanticDescription,
    scene: _Scene | None,
    report: RobotReport,
) -> None:
    """A waypoint where two of the robot's links overlap (the SRDF's disabled pairs left out) is a warning:
    no motion can start or end there, and the usual cause is a pair the SRDF should disable (links that
    touch by design, as MoveIt's setup assistant finds them in the default state). So is a waypoint where
    the robot overlaps the scene's static geometry (a table, a wall): the planner refuses it the same way
    at run time ("goal state is in collision")."""
    from kinema.config.waypoints import Waypoint
    from kinema.config.yamlsource import load_yaml_file
    from kinema.motion.collision import CollisionChecker, self_collision_warning, self_collisions
    from kinema.motion.planning_scene import PlanningScene

    checker = urdf.checker
    if checker is None:
        return  # pinocchio did not load the robot: _check_pinocchio said why
    # The checker was built without the SRDF: its disabled pairs are what the planner allows.
    checker.allowed_collisions = semantic.disabled_collisions
    try:
        srdf = resolved.srdf_path
        path = resolved.waypoints_path
        document = load_yaml_file(path) if path is not None else None
    except KinemaError:
        return  # the checks above report why
    if document is None or not isinstance(document.data, list):
        return
    world: CollisionChecker | None = None
    scene_name = scene.path.name if scene is not None else ""
    if scene is not None:
        try:
            static = PlanningScene.from_mjcf(scene.path, checker.model.link_names, loaded=scene.model)
        except MotionError:
            static = None  # _check_scene said why
        if static is not None and static.objects:
            world = CollisionChecker(checker.model, static)
            world.allowed_collisions = semantic.disabled_collisions
    links = set(checker.model.link_names)
    for number, item in enumerate(document.data):
        try:
            waypoint = Waypoint.from_dict(item, document, number)
        except ConfigError:
            continue
        where = document.location((number, "name"))
        limits = checker.model.limits
        outside = [
            (joint, value, limits[joint])
            for joint, value in waypoint.joint_positions().items()
            if joint in limits and not limits[joint].lower - 1e-6 <= value <= limits[joint].upper + 1e-6
        ]
        for joint, value, limit in outside[:3]:
            report.warnings.append(
                f"{where}: waypoint {waypoint.name!r} has {joint} = {value:g}, outside its limits "
                f"[{limit.lower:.4g}, {limit.upper:.4g}]: the planner refuses it as a goal; move it inside"
            )
        pairs = self_collisions(checker, waypoint.joint_positions())
        if pairs:
            report.warnings.append(
                f"{where}: {self_collision_warning(f'waypoint {waypoint.name!r}', pairs, srdf.name)}"
            )
        if world is not None:
            touching = [p for p in self_collisions(world, waypoint.joint_positions()) if not set(p) <= links]
            if touching:
                overlaps = ", ".join(f"{first} - {second}" for first, second in touching[:4])
                report.warnings.append(
                    f"{where}: waypoint {waypoint.name!r} is in collision with the scene ({overlaps}): no "
                    f"motion can start or end there; move the waypoint, or the object in {scene_name}"
                )


def _joints(names: list[str]) -> str:
    return ("joint " if len(names) == 1 else "joints ") + ", ".join(map(repr, names))


# -- the MuJoCo scene ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Scene:
    """What the checks of the cell need from the loaded scene."""

    path: Path
    joints: list[str]
    actuators: list[str]
    sites: list[str]
    model: Any = None  # the loaded mujoco.MjModel, for the waypoint check against its fixed geometry


def _check_scene(resolved: ResolvedConfig, urdf: _Urdf | None, report: RobotReport) -> _Scene | None:
    path = _attempt(report, lambda: resolved.mujoco_model_path)
    if path is None:
        return None
    report.checked.append(path)
    files = SceneFiles(path, asset_folders(resolved.workspace))
    if not files.check():
        report.problems.extend(files.problems)  # every problem of its files, not only the first
        return None
    model = _attempt(report, files.model)
    if model is None:
        return None
    import mujoco

    def names(kind: Any, count: int) -> list[str]:
        return [mujoco.mj_id2name(model, kind, i) or "" for i in range(count)]

    joints = [
        model.joint(j).name
        for j in range(model.njnt)
        if int(model.jnt_type[j]) in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
    ]
    scene = _Scene(
        path=path,
        joints=joints,
        actuators=names(mujoco.mjtObj.mjOBJ_ACTUATOR, model.nu),
        sites=names(mujoco.mjtObj.mjOBJ_SITE, model.nsite),
        model=model,
    )
    if urdf is not None:
        missing = [j for j in urdf.active_joints if j not in joints]
        if missing:
            report.problem(
                f"the MuJoCo scene does not simulate {_joints(missing)} of {urdf.source.name} (no hinge or "
                f"slide joint of that name); {did_you_mean(missing[0], joints)}",
                path,
            )
    keyframe = resolved.mujoco_keyframe
    keyframes = names(mujoco.mjtObj.mjOBJ_KEY, model.nkey)
    if keyframe and keyframe not in keyframes:
        key = "hardware.simulation.mujoco_keyframe"
        if resolved.get(key) is None:
            key = "hardware.robot_description.urdf_params"
        report.problem(
            f"the MuJoCo keyframe {keyframe!r} is not in the scene {path}; "
            f"{did_you_mean(keyframe, keyframes)}",
            resolved.location_of(key),
        )
    return scene


# -- controllers, gripper, tool frame, sensor -------------------------------------------------------------


def _check_cell(resolved: ResolvedConfig, urdf: _Urdf, scene: _Scene | None, report: RobotReport) -> None:
    from kinema.config.cell import CellSettings

    cell = _attempt(report, lambda: CellSettings.from_config(resolved))
    if cell is None:
        return
    control = _ControlFile(resolved)

    def joint_check(joint: str, what: str, location: SourceLocation) -> None:
        if joint not in urdf.joints:
            report.problem(
                f"{what} names joint {joint!r}, which is not a {urdf.describe('joint')}; "
                f"{did_you_mean(joint, urdf.movable_joints)}",
                location,
            )
        elif scene is not None and joint not in scene.actuators:
            report.problem(
                f"{what} commands joint {joint!r}, which no actuator of the MuJoCo scene {scene.path.name} "
                f"drives (the simulation drives a joint through an actuator named like it); actuators: "
                f"{', '.join(scene.actuators) or 'none'}",
                location,
            )

    for controller in cell.controllers.values():
        for joint in controller.joints:
            joint_check(joint, f"controller {controller.name!r}", control.joints_location(controller.name))
    if cell.gripper is not None:
        joint_check(cell.gripper.joint, "robot.gripper", resolved.location_of("robot.gripper"))
    if cell.tool_frame and cell.tool_frame not in urdf.links:
        report.problem(
            f"robot.tool_frame {cell.tool_frame!r} is not a {urdf.describe('link')}; "
            f"{did_you_mean(cell.tool_frame, urdf.links)}",
            resolved.location_of("robot.tool_frame"),
        )
    sensor = cell.force_torque_sensor
    if sensor is not None and scene is not None:
        for site, key in ((sensor.name, "name"), (sensor.control_site, "control_site")):
            if site and site not in scene.sites:
                location = (
                    resolved.location_of(f"robot.force_torque_sensor.{key}")
                    if resolved.get(f"robot.force_torque_sensor.{key}") is not None
                    else control.location(
                        ("force_torque_sensor_broadcaster", "ros__parameters", "sensor_name")
                    )
                )
                report.problem(
                    f"the force/torque sensor's {key} {site!r} is not a site of the MuJoCo scene "
                    f"{scene.path.name}; {did_you_mean(site, scene.sites)}",
                    location,
                )


class _ControlFile:
    """Where a controller's joints are written: config.yaml's robot.controllers, else ros2_control's yaml."""

    def __init__(self, resolved: ResolvedConfig) -> None:
        self.resolved = resolved
        self.document: Any = None
        if resolved.get("ros2_control.config") is not None:
            from kinema.config.yamlsource import load_yaml_file

            try:
                self.document = load_yaml_file(resolved.resolve_file("ros2_control.config", kind="file"))
            except ConfigError:
                self.document = None  # CellSettings reported it

    def location(self, key: tuple[str, ...]) -> SourceLocation:
        if self.document is not None:
            return self.document.location(key)  # type: ignore[no-any-return]
        return self.resolved.location_of("ros2_control")

    def joints_location(self, controller: str) -> SourceLocation:
        own = ("robot", "controllers", controller, "joints")
        if self.resolved.get(own) is not None:
            return self.resolved.location_of(own)
        if self.document is None:
            return self.resolved.location_of("ros2_control")
        lines = self.document.lines
        key = (controller, "ros__parameters", "joints")
        return self.location(key if key in lines else (controller, "ros__parameters", "joint"))
