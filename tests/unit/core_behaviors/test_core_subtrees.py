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
      <SubTree ID="Move to Pose" _collapsed="true" target_pose="{target_pose}" require_user_approval="true"
        controller_names="joint_trajectory_admittance_controller;franka_gripper_controller" />
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

MOVE_TO_POSE = {
    "target_pose",
    "planning_group_name",
    "ik_frame",
    "link_padding",
    "require_user_approval",
    "controller_names",
    "controller_action_server",
}

# lab_sim's ML objectives call these subtrees of MoveIt Pro's base config (written as they write them).
ML_CALLS = """<root BTCPP_format="4" main_tree_to_execute="ML Calls">
  <BehaviorTree ID="ML Calls">
    <Sequence>
      <SubTree ID="Segment Image from Text Prompt Subtree" _collapsed="true"
        masks_visualization_topic="/masks_visualization" masks2d="{masks2d}" model_package="moveit_pro_sam3"
        text_prompt="conical flask" confidence_threshold="0.5" image_topic_name="/wrist_camera/color" />
      <SubTree ID="Segment Image from No Negative Text Prompt Subtree" _collapsed="true"
        masks_visualization_topic="/masks_visualization" model_package="moveit_pro_sam3"
        confidence_threshold="0.5" text_prompt="an object" image_topic_name="/wrist_camera/color"
        masks2d="{masks2d}" />
      <SubTree ID="Segment Point Cloud from Text Prompt Subtree" _collapsed="true"
        camera_topic_name="/wrist_camera/camera_info" image_topic_name="/wrist_camera/color"
        masks_visualization_topic="/masks_visualization" model_package="moveit_pro_sam3"
        points_topic_name="/wrist_camera/points" text_prompt="an object" confidence_threshold="0.5"
        masks3d="{masks3d}" point_cloud="{point_cloud}" point_cloud_vector="{point_cloud_vector}" />
      <SubTree ID="Segment Point Cloud from Clicked Point Subtree" _collapsed="true"
        camera_topic_name="/wrist_camera/camera_info" decoder_model_path="models/sam2_decoder.onnx"
        encoder_model_path="models/sam2_hiera_large_encoder.onnx" image_topic_name="/wrist_camera/color"
        masks_visualization_topic="/masks_visualization" model_package="moveit_pro_sam2"
        points_topic_name="/wrist_camera/points" />
    </Sequence>
  </BehaviorTree>
</root>
"""

# The ports of MoveIt Pro's SAM3 image subtrees.
SAM3 = {
    "confidence_threshold",
    "decoder_model_path",
    "encoder_model_path",
    "geometry_encoder_model_path",
    "image_topic_name",
    "masks_visualization_topic",
    "masks2d",
    "model_package",
    "text_encoder_model_path",
    "text_prompt",
}

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
    "Move to Pose": MOVE_TO_POSE,
    "Move to Pose (JTC)": MOVE_TO_POSE,
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
    # MoveIt Pro's base config's ML subtrees (their TreeNodesModel ports).
    "Segment Image from Text Prompt Subtree": SAM3,
    "Segment Image from No Negative Text Prompt Subtree": SAM3,
    "Segment Point Cloud from Text Prompt Subtree": (SAM3 - {"masks2d"})
    | {"camera_topic_name", "points_topic_name", "masks3d", "point_cloud", "point_cloud_vector"},
    "Segment Image from Point Subtree": {
        "decoder_model_path",
        "encoder_model_path",
        "image_topic_name",
        "masks_visualization_topic",
        "masks2d",
        "model_package",
        "pixel_coords",
    },
    "Segment Point Cloud from Clicked Point Subtree": {
        "camera_topic_name",
        "decoder_model_path",
        "encoder_model_path",
        "image_topic_name",
        "masks_visualization_topic",
        "model_package",
        "points_topic_name",
    },
    "Create Point Cloud Vector From Masks": {"masks3d", "point_cloud", "point_cloud_vector"},
    "Visualize Segmented Point Cloud": {"masks3d", "point_cloud"},
}


@pytest.fixture(scope="module")
def lab_sim_library():  # type: ignore[no-untyped-def]
    from kinema.config import ObjectiveLibrary, resolve_config
    from kinema.plugins import BehaviorHost

    resolved = resolve_config("lab_sim")
    host = BehaviorHost.for_config(resolved)
    host.load().raise_for_errors()
    return ObjectiveLibrary.load(resolved), host.registry.create_factory()


@pytest.mark.parametrize("xml", [CALLS, ML_CALLS], ids=["motion", "ml"])
def test_moveit_pro_calls_of_the_core_subtrees_validate(lab_sim_library, tmp_path: Path, xml: str) -> None:  # type: ignore[no-untyped-def]
    from kinema.runtime.library_check import file_problem

    library, factory = lab_sim_library
    calls = tmp_path / "calls.xml"
    calls.write_text(xml)
    assert file_problem(library, calls, factory) is None


@pytest.mark.parametrize("subtree", sorted(PORTS))
def test_core_subtrees_declare_moveit_pros_ports(lab_sim_library, subtree: str) -> None:  # type: ignore[no-untyped-def]
    library, _factory = lab_sim_library
    info = library.get(subtree)
    assert info.package == "kinema_objectives" and not info.runnable
    assert {port.name for port in info.ports} == PORTS[subtree]
    assert all(port.description for port in info.ports), "every port says what Kinema does with it"
