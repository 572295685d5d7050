"""Kinema's core subtrees that MoveIt Pro's configurations call: the IDs and ports of MoveIt Pro's closed core
library, so its objectives load unchanged. The calls below are written as MoveIt Pro's public example
objectives write them (hangar_sim, dual_arm_sim, lab_sim at f9f967b7)."""

from __future__ import annotations

from pathlib import Path

import pytest

CALLS = """<root BTCPP_format="4" main_tree_to_execute="Calls">
  <BehaviorTree ID="Calls">
    <Sequence>
      <SubTree ID="Move to Waypoint (JTC)" _collapsed="true" acceleration_scale_factor="1.0"
        controller_action_server="/joint_trajectory_controller/follow_joint_trajectory"
        controller_names="joint_trajectory_controller" joint_group_name="manipulator" link_padding="0.0"
        velocity_scale_factor="1.0" waypoint_name="Look at Table" seed="0" />
      <SubTree ID="Execute MTC Solution (JTC)" controller_names="joint_trajectory_controller"
        solution="{move_to_pose_solution}"
        controller_action_name="/joint_trajectory_controller/follow_joint_trajectory"
        goal_duration_tolerance="-1.0" />
      <SubTree ID="Interpolate to Joint State" _collapsed="false"
        controller_names="joint_trajectory_controller" target_joint_state="{target_joint_state}"
        execution_pipeline="jtc"
        controller_action_server="/joint_trajectory_controller/follow_joint_trajectory"
        acceleration_scale_factor="1.0" />
      <SubTree ID="Move to Pose (JTC)" _collapsed="false" target_pose="{target_pose}" link_padding="0.0"
        planning_group_name="manipulator" ik_frame="grasp_link" require_user_approval="true" />
      <SubTree ID="Request Teleoperation" _collapsed="true" enable_user_interaction="true"
        initial_teleop_mode="4"
        user_interaction_prompt="Teleoperate end effector to grasp pose"
        controller_action_server="/joint_trajectory_admittance_controller/follow_joint_trajectory"
        max_ik_solutions="8" max_mtc_solutions="1"
        joint_trajectory_controller_name="joint_trajectory_admittance_controller"
        default_planning_group="manipulator" default_ik_frame="grasp_link" link_padding="0.01"
        execution_pipeline="jtac" />
    </Sequence>
  </BehaviorTree>
</root>
"""

# Each subtree's ports: MoveIt Pro's (the ports its callers pass), and Kinema's own (marked in descriptions).
PORTS = {
    "Move to Waypoint (JTC)": {
        "waypoint_name",
        "joint_group_name",
        "link_padding",
        "velocity_scale_factor",
        "acceleration_scale_factor",
        "controller_names",
        "controller_action_server",
        "seed",
    },
    "Execute MTC Solution (JTC)": {
        "solution",
        "controller_names",
        "controller_action_name",
        "goal_duration_tolerance",
    },
    "Interpolate to Joint State": {
        "target_joint_state",
        "joint_group_name",
        "link_padding",
        "velocity_scale_factor",
        "acceleration_scale_factor",
        "controller_names",
        "controller_action_server",
        "execution_pipeline",
    },
    "Move to Pose (JTC)": {
        "target_pose",
        "planning_group_name",
        "ik_frame",
        "link_padding",
        "require_user_approval",
        "controller_names",
        "controller_action_server",
    },
    "Request Teleoperation": {
        "enable_user_interaction",
        "user_interaction_prompt",
        "initial_teleop_mode",
        "controller_action_server",
        "max_ik_solutions",
        "max_mtc_solutions",
        "joint_trajectory_controller_name",
        "default_planning_group",
        "default_ik_frame",
        "link_padding",
        "execution_pipeline",
        "gripper_open_position",
        "gripper_closed_position",
    },
}


@pytest.fixture(scope="module")
def lab_sim_library():  # type: ignore[no-untyped-def]
    from kinema.config import ObjectiveLibrary, resolve_config
    from kinema.plugins import BehaviorHost

    resolved = resolve_config("lab_sim")
    host = BehaviorHost.for_config(resolved)
    host.load().raise_for_errors()
    return ObjectiveLibrary.load(resolved), host.registry.create_factory()


def test_moveit_pro_calls_of_the_core_subtrees_validate(lab_sim_library, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    from kinema.runtime.library_check import file_problem

    library, factory = lab_sim_library
    calls = tmp_path / "calls.xml"
    calls.write_text(CALLS)
    assert file_problem(library, calls, factory) is None


@pytest.mark.parametrize("subtree", sorted(PORTS))
def test_core_subtrees_declare_moveit_pros_ports(lab_sim_library, subtree: str) -> None:  # type: ignore[no-untyped-def]
    library, _factory = lab_sim_library
    info = library.get(subtree)
    assert info.package == "kinema_objectives" and not info.runnable
    assert {port.name for port in info.ports} == PORTS[subtree]
    assert all(port.description for port in info.ports), "every port says what Kinema does with it"
