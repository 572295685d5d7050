"""The pose, planning-scene and motion behaviors have every port MoveIt Pro's lab_sim objectives set on them
(reference inventory §5.3), in the direction the objectives use them."""

from __future__ import annotations

import pytest

from kinema.bt.ports import PortDirection
from kinema.plugins import BehaviorRegistry

IN, OUT = PortDirection.INPUT, PortDirection.OUTPUT
PORTS = {
    "TransformPoseFrame": {"input_pose": IN, "output_pose": OUT, "target_frame_id": IN},
    "TransformPoseWithPose": {"input_pose": IN, "transform_pose": IN, "output_pose": OUT},
    "CalculatePoseOffset": {"source_pose": IN, "destination_pose": IN, "source_to_destination_pose": OUT},
    "ComputeLinkPoseForwardKinematics": {
        "joint_state": IN,
        "link_name": IN,
        "link_pose": OUT,
        "planning_scene": IN,
    },
    "GetCurrentPlanningScene": {"planning_scene_msg": OUT},
    "AddCollisionBox": {"object_id": IN, "dimensions": IN, "pose": IN, "overwrite": IN},
    "AddCollisionObject": {"collision_object": IN, "overwrite": IN},
    "IsCollisionObjectInPlanningScene": {"planning_scene": IN, "collision_object_name": IN},
    "GetRobotStateFromTrajectory": {
        "from_start": IN,
        "joint_state": OUT,
        "joint_trajectory_msg": IN,
        "time_from_reference": IN,
    },
    "CreateStationaryTrajectory": {"joint_state": IN, "joint_trajectory_msg": OUT, "trajectory_duration": IN},
    "ValidateTrajectory": {
        "cartesian_space_step": IN,
        "joint_space_step": IN,
        "joint_trajectory_msg": IN,
        "planning_group_name": IN,
        "planning_scene_msg": IN,
        "debug_solution": OUT,
    },
    "PlanCartesianPath": {
        "blending_radius": IN,
        "debug_solution": OUT,
        "ik_cartesian_space_density": IN,
        "ik_joint_space_density": IN,
        "joint_trajectory_msg": OUT,
        "path": IN,
        "planning_group_name": IN,
        "position_only": IN,
        "tip_links": IN,
        "trajectory_timing": IN,
        "tip_offset": IN,
        "max_optimizer_iterations": IN,
    },
    "GetJointState": {"joint_state": OUT, "planning_scene": IN, "planning_group_name": IN},
    "ExecuteTrajectory": {
        "joint_trajectory_msg": IN,
        "goal_duration_tolerance": IN,
        "controller_action_name": IN,
        "execution_pipeline": IN,
        "absolute_force_torque_threshold": IN,
        "admittance_parameters_msg": IN,
        "goal_position_tolerance": IN,
        "path_position_tolerance": IN,
    },
    "ExecuteTrajectoryWithAdmittance": {
        "joint_trajectory_msg": IN,
        "controller_action_name": IN,
        "absolute_force_torque_threshold": IN,
        "admittance_parameters_msg": IN,
        "goal_position_tolerance": IN,
        "path_position_tolerance": IN,
    },
    "SetAdmittanceParameters": {"admittance_parameters_msg": OUT, "config_file_name": IN},
}


@pytest.mark.parametrize("behavior_id", sorted(PORTS))
def test_ports_and_directions(registry: BehaviorRegistry, behavior_id: str) -> None:
    manifest = registry[behavior_id].cls
    ports = {p.name: p.direction for p in manifest.provided_ports()}
    for name, direction in PORTS[behavior_id].items():
        assert name in ports, f"{behavior_id} lacks port {name}; it has {sorted(ports)}"
        assert ports[name] == direction, f"{behavior_id}.{name} is {ports[name]}, the corpus uses {direction}"


@pytest.mark.parametrize("behavior_id", sorted(PORTS))
def test_description_and_subcategory(registry: BehaviorRegistry, behavior_id: str) -> None:
    metadata = registry[behavior_id].cls.metadata()
    assert metadata["subcategory"] and len(metadata["description"]) > 20, metadata
