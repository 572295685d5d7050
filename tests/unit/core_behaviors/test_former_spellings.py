"""MoveIt Pro's former behavior and port names: objectives written with them build as today's behaviors."""

from __future__ import annotations

from typing import Any

import pytest

from kinema.bt import Blackboard, NodeStatus
from kinema.errors import KinemaError
from kinema.plugins import BehaviorRegistry


def _tree(node_xml: str) -> str:
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Old">\n'
        '  <BehaviorTree ID="Old">\n'
        f"    {node_xml}\n"
        "  </BehaviorTree>\n"
        "</root>\n"
    )


def _built(registry: BehaviorRegistry, node_xml: str) -> tuple[Any, Any]:
    """The first node the old spelling builds to, and the factory (its notes)."""
    factory = registry.create_factory()
    tree = factory.create_tree_from_text(_tree(node_xml), filename="old.xml")
    return next(iter(tree.nodes())), factory


# (as an old objective writes it, today's ID, a port it must reach under today's name and its value)
RENAMED = [
    (
        '<Action ID="CreateStampedPose" position_xyz="1;2;3" stamped_pose="{p}"/>',
        "CreatePoseStamped",
        ("pose_stamped", "{p}"),
    ),
    ('<CreateStampedTwist stamped_twist="{t}"/>', "CreateTwistStamped", ("twist_stamped", "{t}")),
    (
        '<Action ID="CreateStampedWrench" stamped_wrench="{w}"/>',
        "CreateWrenchStamped",
        ("wrench_stamped", "{w}"),
    ),
    (
        '<Action ID="ActivateControllers" controller_names="joint_trajectory_controller"/>',
        "SwitchController",
        ("activate_controllers", "joint_trajectory_controller"),
    ),
    (
        '<Action ID="ExecuteFollowJointTrajectory" joint_trajectory_msg="{traj}" '
        'execute_follow_joint_trajectory_action_name="/arm/follow_joint_trajectory"/>',
        "ExecuteTrajectory",
        ("controller_action_name", "/arm/follow_joint_trajectory"),
    ),
    (
        '<Action ID="WaitForUserTrajectoryApproval" solution="{s}"/>',
        "WaitForMTCSolutionApproval",
        ("solution", "{s}"),
    ),
    (
        '<Action ID="SetupMTCInterpolateToJointState" joint_state="{goal}"/>',
        "SetupMTCPlanToRobotState",
        ("joint_state", "{goal}"),
    ),
    (
        '<Action ID="SetupMTCPlanToJointState" joint_state="{goal}" max_iterations="5000"/>',
        "SetupMTCPlanToRobotState",
        ("max_iterations", "5000"),
    ),
    (
        '<Action ID="PublishStaticFrame" child_frame_id="local"/>',
        "PublishTF",
        ("child_frame_id", "local"),
    ),
    ('<Action ID="CreateJointState" joint_names="a" positions="1"/>', "CreateRobotState", ("positions", "1")),
    ('<Action ID="GetRobotJointState" joint_state="{js}"/>', "GetJointState", ("joint_state", "{js}")),
    (
        '<Action ID="GetTrajectoryStateAtTime" joint_trajectory_msg="{t}"/>',
        "GetRobotStateFromTrajectory",
        ("joint_trajectory_msg", "{t}"),
    ),
    ('<Action ID="DetectAprilTags" apriltag_size="0.051"/>', "DetectAprilTags", ("tag_size", "0.051")),
    (
        '<Action ID="SetupMTCUpdateGroupCollisionRule" group_name="gripper" object_name="&lt;octomap&gt;" '
        'allow_collision="true" task="{t}"/>',
        "SetupMTCSetCollisionRule",
        ("name_b", "<octomap>"),
    ),
    ('<Action ID="GetImage" timeout_sec="3"/>', "GetImage", ("message_timeout_sec", "3")),
    ('<Action ID="GetPointCloud" timeout_sec="4"/>', "GetPointCloud", ("message_timeout_sec", "4")),
    ('<Action ID="GetCameraInfo" timeout_sec="6"/>', "GetCameraInfo", ("message_timeout_sec", "6")),
]


@pytest.mark.parametrize(("old", "current", "port"), RENAMED, ids=[row[1] + "<-old" for row in RENAMED])
def test_an_old_spelling_builds_the_current_behavior_with_its_ports(
    registry: BehaviorRegistry, old: str, current: str, port: tuple[str, str]
) -> None:
    node, factory = _built(registry, old)
    assert node.registration_id == current
    name, value = port
    ports = {**(node.config.input_ports or {}), **(node.config.output_ports or {})}
    assert ports[name] == value
    (note,) = factory.library.spelling_notes
    assert str(note).startswith("old.xml:3: ") and current in note.message and "old" in note.message


def test_create_stamped_pose_writes_the_pose_to_its_old_output_port(registry: BehaviorRegistry) -> None:
    factory = registry.create_factory()
    blackboard = Blackboard.create()
    xml = _tree(
        '<Action ID="CreateStampedPose" reference_frame="base" position_xyz="1;2;3" stamped_pose="{p}"/>'
    )
    tree = factory.create_tree_from_text(xml, blackboard, filename="old.xml")
    assert tree.tick_once() is NodeStatus.SUCCESS
    pose = blackboard.get("p")
    assert pose.header.frame_id == "base"
    assert [pose.pose.position.x, pose.pose.position.y, pose.pose.position.z] == [1.0, 2.0, 3.0]
    message = factory.library.spelling_notes[0].message
    assert message.startswith("CreateStampedPose is MoveIt Pro's old name of CreatePoseStamped")
    assert "stamped_pose is pose_stamped" in message


def test_execute_mtc_task_is_the_execute_mtc_solution_subtree(registry: BehaviorRegistry) -> None:
    factory = registry.create_factory()
    factory.register_behavior_tree_from_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Execute MTC Solution">'
        '<Action ID="WaitForMTCSolutionApproval" solution="{solution}"/></BehaviorTree></root>',
        filename="execute_mtc_solution.xml",
    )
    tree = factory.create_tree_from_text(
        _tree('<Action ID="ExecuteMTCTask" solution="{plan}"/>'), filename="old.xml"
    )
    node = next(iter(tree.nodes()))
    assert node.registration_id == "SubTree" and node.subtree_id == "Execute MTC Solution"
    (note,) = factory.library.spelling_notes
    assert "ExecuteMTCTask is MoveIt Pro's old name of the SubTree 'Execute MTC Solution'" in note.message


def test_move_to_waypoint_is_the_move_to_waypoint_subtree(registry: BehaviorRegistry) -> None:
    """MoveIt Studio's objectives moved with a MoveToWaypoint behavior; today it is the "Move to Waypoint"
    subtree, whose joint_group_name was its planning_group_name."""
    factory = registry.create_factory()
    factory.register_behavior_tree_from_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Move to Waypoint">'
        '<Action ID="RetrieveWaypoint" waypoint_name="{waypoint_name}"'
        ' joint_group_name="{joint_group_name}"/></BehaviorTree></root>',
        filename="move_to_waypoint.xml",
    )
    tree = factory.create_tree_from_text(
        _tree('<Action ID="MoveToWaypoint" waypoint_name="Home" planning_group_name="manipulator"/>'),
        filename="old.xml",
    )
    node = next(iter(tree.nodes()))
    assert node.registration_id == "SubTree" and node.subtree_id == "Move to Waypoint"
    (note,) = factory.library.spelling_notes
    assert "MoveToWaypoint is MoveIt Pro's old name of the SubTree 'Move to Waypoint'" in note.message
    assert "planning_group_name is joint_group_name" in note.message


@pytest.mark.parametrize(
    ("old", "current", "ignored"),
    [
        ('<Action ID="InitializeMTCTask" controller_names="a;b"/>', "InitializeMTCTask", "controller_names"),
        ('<Action ID="DetectAprilTags" parameters="{parameters}"/>', "DetectAprilTags", "parameters"),
        (
            '<Action ID="PlanToJointGoal" keep_orientation="false" keep_orientation_tolerance="0.05"/>',
            "PlanToJointGoal",
            "keep_orientation",
        ),
    ],
)
def test_a_port_without_counterpart_is_dropped_with_its_reason(
    registry: BehaviorRegistry, old: str, current: str, ignored: str
) -> None:
    node, factory = _built(registry, old)
    assert node.registration_id == current
    assert ignored not in (node.config.input_ports or {})
    (note,) = factory.library.spelling_notes
    assert f"Kinema ignores {ignored}" in note.message or f"Kinema ignores them ({ignored}" in note.message


@pytest.mark.parametrize("value", ["true", "{keep_orientation}"])
def test_keep_orientation_that_may_be_true_is_refused_not_dropped(
    registry: BehaviorRegistry, value: str
) -> None:
    factory = registry.create_factory()
    with pytest.raises(KinemaError) as raised:
        factory.create_tree_from_text(
            _tree(f'<Action ID="PlanToJointGoal" keep_orientation="{value}"/>'), filename="old.xml"
        )
    assert str(raised.value).startswith("old.xml:3: ")
    assert "cannot honour it" in str(raised.value) and "orientation" in str(raised.value)


def test_an_objective_in_current_spelling_leaves_no_note(registry: BehaviorRegistry) -> None:
    _, factory = _built(registry, '<Action ID="GetImage" message_timeout_sec="3"/>')
    assert not factory.library.spelling_notes


def test_an_objective_file_in_old_spelling_runs_on_the_objective_server(
    registry: BehaviorRegistry, tmp_path: Any
) -> None:
    from types import SimpleNamespace

    from kinema.bt import WallClock
    from kinema.runtime.objective_server import ObjectiveRequest, ObjectiveServer
    from kinema.runtime.objective_source import LibraryTreeSource, library_from_folders

    (tmp_path / "old.xml").write_text(
        _tree(
            '<Sequence><Action ID="CreateStampedPose" position_xyz="1;2;3" stamped_pose="{p}"/>'
            '<Action ID="CreateStampedTwist" stamped_twist="{t}"/></Sequence>'
        )
    )
    source = LibraryTreeSource(
        lambda: library_from_folders([tmp_path]),
        host=SimpleNamespace(registry=registry),
        context=None,
        clock=WallClock(),
    )
    assert source.objective_names() == ["Old"]
    with ObjectiveServer(source) as server:
        result = server.submit(ObjectiveRequest("Old")).wait(5)
    assert result is not None and result.succeeded, result


def test_the_old_one_stage_pick_is_refused_with_how_to_write_it_today(registry: BehaviorRegistry) -> None:
    factory = registry.create_factory()
    with pytest.raises(KinemaError) as raised:
        factory.create_tree_from_text(
            _tree('<Action ID="SetupMTCPickObject" grasp_pose="{g}" task="{t}" parameters="{p}"/>'),
            filename="old.xml",
        )
    text = str(raised.value)
    assert text.startswith("old.xml:3: SetupMTCPickObject is MoveIt Pro's removed behavior")
    assert "moves no gripper" in text and "SetupMTCBatchPoseIK" in text and "'Close Gripper'" in text


def test_retrieve_joint_state_parameter_is_read_as_retrieve_robot_state_parameter(
    registry: BehaviorRegistry,
) -> None:
    factory = registry.create_factory()
    tree = factory.create_tree_from_text(
        _tree('<Action ID="RetrieveJointStateParameter" timeout_sec="2" joint_state="{j}"/>'),
        filename="old.xml",
    )
    assert next(iter(tree.nodes())).registration_id == "RetrieveRobotStateParameter"
    (note,) = factory.library.spelling_notes
    assert "RetrieveJointStateParameter is MoveIt Pro's old name of RetrieveRobotStateParameter" in str(note)


APRILTAG_PARAMETERS = """DetectAprilTags:
  apriltag_family_name: 36h11
  apriltag_size: 0.051
  max_hamming: 0
  refine_edges: false
  z_up: true
"""


def test_load_objective_parameters_gives_each_behavior_its_section_as_ports(
    registry: BehaviorRegistry, tmp_path: Any
) -> None:
    (tmp_path / "apriltag_detection_config.yaml").write_text(APRILTAG_PARAMETERS)
    objective = tmp_path / "old.xml"
    objective.write_text(
        _tree(
            "<Sequence>"
            '<Action ID="LoadObjectiveParameters" config_file_name="apriltag_detection_config.yaml" '
            'parameters="{parameters}"/>'
            '<Action ID="DetectAprilTags" image="{image}" camera_info="{info}" parameters="{parameters}" '
            'max_hamming="2"/>'
            "</Sequence>"
        )
    )
    factory = registry.create_factory()
    tree = factory.create_tree_from_file(objective)
    loader, detector = [n for n in tree.nodes() if n.registration_id != "Sequence"]
    assert loader.registration_id == "AlwaysSuccess"
    ports = detector.config.input_ports
    assert (ports["tag_size"], ports["apriltag_family_name"], ports["refine_edges"]) == (
        "0.051",
        "36h11",
        "false",
    )
    assert ports["max_hamming"] == "2"  # what the objective sets itself wins
    assert "parameters" not in ports and "z_up" not in ports
    notes = [note.message for note in factory.library.spelling_notes]
    assert any("Kinema reads apriltag_detection_config.yaml when the objective loads" in n for n in notes)
    assert any("no port for z_up" in n and "tag_size=0.051" in n for n in notes)


def test_load_objective_parameters_without_its_file_names_where_it_looked(
    registry: BehaviorRegistry, tmp_path: Any
) -> None:
    objective = tmp_path / "old.xml"
    objective.write_text(_tree('<Action ID="LoadObjectiveParameters" config_file_name="gone.yaml"/>'))
    with pytest.raises(KinemaError) as raised:
        registry.create_factory().create_tree_from_file(objective)
    assert "no file 'gone.yaml' beside the objective" in str(raised.value) and str(tmp_path) in str(
        raised.value
    )


def test_validating_a_file_whose_parameter_file_is_missing_reports_its_other_problems_too(
    registry: BehaviorRegistry, tmp_path: Any
) -> None:
    """A MoveIt Pro objective without its YAML showed only that; with the YAML, nine more problems showed.
    Validation names the missing file and goes on (a run still stops at it, as above)."""
    from kinema.bt.validation import validate_files

    objective = tmp_path / "old.xml"
    objective.write_text(
        _tree(
            '<Sequence><Action ID="LoadObjectiveParameters" config_file_name="gone.yaml"/>'
            '<Action ID="DetectAprilTags" parameters="{parameters}"/><NoSuchBehavior/></Sequence>'
        )
    )
    problems = [str(problem) for problem in validate_files([objective], registry.create_factory())]
    assert any("no file 'gone.yaml' beside the objective" in p for p in problems), problems
    assert any("Node not recognized: NoSuchBehavior" in p for p in problems), problems
    # The behavior that took {parameters} is not also said to lack a `parameters` port.
    assert not any("parameters" in p and "DetectAprilTags" in p for p in problems), problems
