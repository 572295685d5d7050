"""The bundled interfaces: MoveIt Pro's public names and fields, loaded once, shipped as package data."""

from __future__ import annotations

from pathlib import Path

import pytest

from kinema.errors import TransportError
from kinema.interfaces import TypeRegistry, interfaces_dir, load_interfaces


def _fields(type_name: str) -> list[str]:
    return [name for name, _ in load_interfaces().fields(type_name)]


def test_sdk_interfaces_have_moveit_pro_fields() -> None:
    assert _fields("moveit_studio_sdk_msgs/srv/ExecuteObjective_Request") == [
        "objective_name",
        "parameter_overrides",
    ]
    assert _fields("moveit_studio_sdk_msgs/srv/ExecuteObjective_Response") == ["error_code"]
    assert _fields("moveit_studio_sdk_msgs/srv/CancelObjective_Response") == ["status"]
    assert _fields("moveit_studio_sdk_msgs/action/DoObjectiveSequence_Goal") == [
        "objective_name",
        "objective_xml_string",
        "parameter_overrides",
    ]
    assert _fields("moveit_studio_sdk_msgs/action/DoObjectiveSequence_Result") == [
        "error_code",
        "error_message",
    ]
    assert _fields("moveit_studio_sdk_msgs/msg/BehaviorParameter") == [
        "description",
        "string_value",
        "pose_value",
        "double_value",
        "int_value",
        "bool_value",
        "joint_state_value",
        "behavior_namespaces",
    ]
    assert _fields("moveit_msgs/msg/MoveItErrorCodes") == ["val", "message", "source"]
    assert _fields("moveit_studio_agent_msgs/msg/ObjectiveServerStatus") == [
        "process_timestamp",
        "ros_timestamp",
        "objective_name",
        "objective_status",
    ]


def test_every_kind_is_registered() -> None:
    registry = load_interfaces()
    for service in (
        "moveit_studio_sdk_msgs/srv/ExecuteObjective",
        "moveit_studio_sdk_msgs/srv/CancelObjective",
        "moveit_studio_agent_msgs/srv/GetWaypoints",
        "moveit_studio_agent_msgs/srv/EditWaypoints",
        "example_interfaces/srv/AddTwoInts",
        "controller_manager_msgs/srv/ListControllers",
        "controller_manager_msgs/srv/SwitchController",
        "kinema_msgs/srv/ListObjectives",
    ):
        assert registry.service(service).name == service
    for action in (
        "moveit_studio_sdk_msgs/action/DoObjectiveSequence",
        "control_msgs/action/FollowJointTrajectory",
        "control_msgs/action/GripperCommand",
    ):
        assert registry.action(action).name == action
    for message in (
        "moveit_studio_agent_msgs/msg/Log",
        "kinema_msgs/msg/BlackboardSnapshot",
        "rosgraph_msgs/msg/Clock",
    ):
        assert registry.message_type(message) == message


def test_loading_is_cached() -> None:
    assert load_interfaces() is load_interfaces()


def test_files_ship_inside_the_package() -> None:
    root = interfaces_dir()
    assert (root / "moveit_studio_sdk_msgs" / "action" / "DoObjectiveSequence.action").is_file()
    assert root.parent.name == "kinema"


def test_packages_load_on_first_use() -> None:
    registry = TypeRegistry()
    registry.add_directory(interfaces_dir())
    assert "moveit_studio_sdk_msgs/msg/RequestStatus" not in registry.typestore.fielddefs
    execute = registry.service("moveit_studio_sdk_msgs/srv/ExecuteObjective")
    assert execute.request in registry.typestore.fielddefs
    assert "moveit_msgs/msg/MoveItErrorCodes" in registry.typestore.fielddefs  # a dependency
    assert "kinema_msgs/msg/ObjectiveInfo" not in registry.typestore.fielddefs
    assert "kinema_msgs/srv/ListObjectives" in registry.names("srv")  # listing loads everything


def test_bad_interface_files_are_reported_with_their_path(tmp_path: Path) -> None:
    (tmp_path / "std_msgs" / "msg").mkdir(parents=True)
    (tmp_path / "std_msgs" / "msg" / "String.msg").write_text("int32 data\n")
    (tmp_path / "mine" / "msg").mkdir(parents=True)
    (tmp_path / "mine" / "msg" / "Thing.msg").write_text("Missing part\n")
    registry = TypeRegistry()
    registry.add_directory(tmp_path)
    with pytest.raises(TransportError, match=r"String\.msg: std_msgs/msg/String is already defined"):
        registry.message_type("std_msgs/msg/String")
    with pytest.raises(TransportError, match=r"Thing\.msg: field 'part' of mine/msg/Thing uses unknown type"):
        registry.message_type("mine/msg/Thing")
