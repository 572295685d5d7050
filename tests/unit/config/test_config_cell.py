"""A cell's robot settings come from its config package: config.yaml's robot section, MoveIt Pro's
ros2_control yaml, moveit_params; nothing robot-specific comes from code."""

from __future__ import annotations

import textwrap

import pytest
from tests.unit.config.conftest import WorkspaceBuilder

from kinema.behaviors.cell_ports import cell_input_port, resolve_cell_ports
from kinema.config import Workspace, resolve_config
from kinema.config.cell import (
    GRIPPER_ACTION_CONTROLLER,
    JOINT_TRAJECTORY_CONTROLLER,
    CellSettings,
    substitute_config_defaults,
)
from kinema.errors import ConfigError


def _cell(ws: WorkspaceBuilder, name: str, extra: dict) -> CellSettings:
    data = ws.root_data(name)
    data.update(extra)
    ws.config(name, data)
    return CellSettings.from_config(resolve_config(name, Workspace.discover(ws.root), check_files=False))


def test_lab_sim_states_its_own_robot_values() -> None:
    cell = CellSettings.from_config(resolve_config("lab_sim", None))
    assert cell.planning_group == "manipulator"
    assert cell.tool_frame == "grasp_link"
    assert cell.gripper is not None and cell.gripper.action == "/robotiq_gripper_controller/gripper_cmd"
    assert (cell.gripper.open_position, cell.gripper.closed_position) == (0.0, 0.7929)
    assert cell.controllers["robotiq_gripper_controller"].type == GRIPPER_ACTION_CONTROLLER
    assert cell.controllers["velocity_force_controller"].active is False


def test_a_robot_without_a_gripper_or_sensor_has_none(ws: WorkspaceBuilder) -> None:
    cell = _cell(ws, "plain", {"moveit_params": {"joint_group_name": "arm"}})
    assert cell.planning_group == "arm"
    assert cell.gripper is None and cell.force_torque_sensor is None and cell.tool_frame is None
    assert cell.value("gripper_action") is None


def test_controllers_and_gripper_come_from_the_config(ws: WorkspaceBuilder) -> None:
    cell = _cell(
        ws,
        "panda_cell",
        {
            "moveit_params": {"joint_group_name": "arm"},
            "ros2_control": {
                "controllers_active_at_startup": [
                    "joint_state_broadcaster",
                    "arm_controller",
                    "hand_controller",
                ]
            },
            "robot": {
                "tool_frame": "panda_hand_tcp",
                "gripper": {
                    "controller": "hand_controller",
                    "joint": "panda_finger_joint1",
                    "open_position": 0.04,
                    "closed_position": 0.0,
                },
                "controllers": {
                    "arm_controller": {"type": JOINT_TRAJECTORY_CONTROLLER, "joints": ["j1", "j2"]},
                },
            },
        },
    )
    assert cell.gripper is not None and cell.gripper.action == "/hand_controller/gripper_cmd"
    assert cell.controllers["hand_controller"].type == GRIPPER_ACTION_CONTROLLER
    assert cell.controllers["arm_controller"].joints == ("j1", "j2")
    assert cell.value("tool_frame") == "panda_hand_tcp"


def test_a_controller_of_unknown_type_is_an_error_naming_the_types(ws: WorkspaceBuilder) -> None:
    with pytest.raises(
        ConfigError, match=r"controller 'arm_controller' has no type.*JointTrajectoryController"
    ):
        _cell(ws, "typeless", {"ros2_control": {"controllers_active_at_startup": ["arm_controller"]}})


def test_a_gripper_without_its_positions_names_what_is_missing(ws: WorkspaceBuilder) -> None:
    with pytest.raises(
        ConfigError, match=r"config.yaml:\d+: robot.gripper lacks open_position, closed_position"
    ):
        _cell(ws, "half", {"robot": {"gripper": {"controller": "hand", "joint": "f"}}})


def test_moveit_pros_ros2_control_yaml_gives_types_joints_and_the_sensor(ws: WorkspaceBuilder) -> None:
    folder = ws.config("ctl", ws.root_data("ctl"))
    (folder / "config" / "control.yaml").write_text(
        textwrap.dedent(
            """
            controller_manager:
              ros__parameters:
                my_jtc: {type: joint_trajectory_controller/JointTrajectoryController}
                grip: {type: parallel_gripper_action_controller/GripperActionController}
            my_jtc:
              ros__parameters:
                joints: [a, b]
            grip:
              ros__parameters:
                joint: finger
            force_torque_sensor_broadcaster:
              ros__parameters:
                sensor_name: wrist_fts
                frame_id: tool0
            joint_trajectory_admittance_controller:
              ros__parameters:
                ee_frame: tcp
                default_absolute_force_torque_threshold: [30.0, 30.0, 30.0, 5.0, 5.0, 5.0]
            """
        )
    )
    data = ws.root_data("ctl")
    data["ros2_control"] = {
        "config": {"package": "ctl", "path": "config/control.yaml"},
        "controllers_active_at_startup": ["my_jtc", "grip"],
        "controllers_inactive_at_startup": ["joint_trajectory_admittance_controller"],
    }
    data["robot"] = {"gripper": {"controller": "grip", "open_position": 0.0, "closed_position": 0.8}}
    ws.config("ctl", data)
    cell = CellSettings.from_config(resolve_config("ctl", Workspace.discover(ws.root), check_files=False))
    assert cell.controllers["my_jtc"].joints == ("a", "b")
    assert cell.controllers["grip"].type == GRIPPER_ACTION_CONTROLLER
    assert cell.gripper is not None and cell.gripper.joint == "finger"
    assert cell.force_torque_sensor is not None and cell.force_torque_sensor.name == "wrist_fts"
    assert cell.force_torque_sensor.frame == "tool0"
    # A controller's own parameters travel with it, for the driver to read what it simulates.
    admittance = cell.controllers["joint_trajectory_admittance_controller"]
    assert admittance.parameters["ee_frame"] == "tcp" and not admittance.active
    assert admittance.parameters["default_absolute_force_torque_threshold"][3] == 5.0
    assert cell.value("admittance_controller_action") == (
        "/joint_trajectory_admittance_controller/follow_joint_trajectory"
    )


def test_a_cell_port_defaults_to_the_config_value_and_has_none_without_it() -> None:
    ports = [cell_input_port("planning_group_name", str, "planning_group", "The group.")]
    assert not ports[0].has_default
    assert "moveit_params.joint_group_name" in ports[0].description
    resolved = resolve_cell_ports(ports, CellSettings(planning_group="panda_arm"))
    assert resolved[0].default_str == "panda_arm"
    assert not resolve_cell_ports(ports, CellSettings())[0].has_default


def test_a_subtree_default_can_name_a_config_key() -> None:
    from kinema.bt import BehaviorTreeFactory

    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(
        """<root BTCPP_format="4"><BehaviorTree ID="T"><AlwaysSuccess/></BehaviorTree>
        <TreeNodesModel><SubTree ID="T">
          <input_port name="group" default="$(config moveit_params.joint_group_name)"/>
          <input_port name="image" default="/$(config robot.default_camera)/color"/>
          <input_port name="unset" default="/$(config robot.no_such_key)/color"/>
        </SubTree></TreeNodesModel></root>"""
    )
    substitute_config_defaults(factory.library.subtree_models, resolve_config("lab_sim", None))
    ports = factory.library.subtree_models["T"].ports
    assert ports["group"].default_str == "manipulator"
    # Inside a longer default too (a camera's topic); a key the config does not set leaves no default.
    assert ports["image"].default_str == "/wrist_camera/color"
    assert ports["unset"].default_str == ""
