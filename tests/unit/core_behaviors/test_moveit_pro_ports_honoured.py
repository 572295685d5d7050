"""Ports MoveIt Pro's objectives set that Kinema used to refuse, and now honours:
WaitForMTCSolutionApproval.cartesian_path_links, SetupMTCPlanToRobotState's planning ports,
SavePoseStampedToYaml.namespace, MergePointClouds.icp_*, PlanCartesianPath.{tip_link,
trajectory_sampling_rate}."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import publish_repeatedly, tick_behavior
from kinema.transport import from_dict

ARM = [
    "linear_rail_joint",
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
]
HOME = [0.0, 0.0, -2.0, 2.0, -1.5708, -1.5708, 0.0]
MID = [-0.1333, 0.0, -1.25758, 1.37827, -1.69149, -1.5708, 0.0]


@pytest.fixture
def at_home(context: BehaviorContext) -> Iterator[None]:
    state = {"name": [*ARM, "robotiq_85_left_knuckle_joint"], "position": [*HOME, 0.0]}
    with publish_repeatedly(context.node, "sensor_msgs/msg/JointState", "/joint_states", state):
        yield


def _q(model: Any, arm: list[float]) -> np.ndarray:
    return model.configuration(dict(zip(ARM, arm, strict=True)))


def _seconds(stamp: Any) -> float:
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9


# -- WaitForMTCSolutionApproval.cartesian_path_links ------------------------------------------------------


def test_the_paths_of_the_links_named_are_drawn_for_approval(
    behavior: Any, context: BehaviorContext, monkeypatch: pytest.MonkeyPatch, lab_sim_model: Any
) -> None:
    from kinema.motion import fk

    monkeypatch.setenv("KINEMA_AUTO_APPROVE", "1")
    lines: list[Any] = []
    context.node.create_subscription(
        "visualization_msgs/msg/MarkerArray",
        "/visualization_marker_array",
        lambda m: lines.extend(x for x in m.markers if x.action == 0),
    )
    trajectory = from_dict(
        "trajectory_msgs/msg/JointTrajectory",
        {
            "joint_names": ARM,
            "points": [
                {"positions": list(np.add(HOME, np.subtract(MID, HOME) * t)), "time_from_start": {"sec": k}}
                for k, t in enumerate(np.linspace(0.0, 1.0, 5))
            ],
        },
    )
    run = tick_behavior(
        behavior("WaitForMTCSolutionApproval"),
        {"solution": trajectory, "cartesian_path_links": ["grasp_link", "tool0", "tool9"]},
        context=context,
    )
    assert run.status == NodeStatus.SUCCESS
    assert "'tool9', which is no link of the robot" in run.toasts[0]
    _wait(lambda: len(lines) >= 2)
    by_label = {line.text: line for line in lines}
    assert set(by_label) == {"grasp_link", "tool0"}
    end = fk(lab_sim_model, _q(lab_sim_model, MID), "tool0")[:3, 3]
    last = by_label["tool0"].points[-1]
    np.testing.assert_allclose([last.x, last.y, last.z], end, atol=1e-6)
    assert len(by_label["grasp_link"].points) == 5


def _wait(predicate: Any, timeout: float = 10.0) -> None:
    import time

    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.01)


# -- SetupMTCPlanToRobotState -----------------------------------------------------------------------------


def test_plan_to_robot_state_plans_with_the_ports_it_is_given(
    behavior: Any, context: BehaviorContext, at_home: None
) -> None:
    goal = from_dict("sensor_msgs/msg/JointState", {"name": ARM, "position": MID})

    def plan(**ports: Any) -> Any:
        task = tick_behavior(behavior("InitializeMTCTask"), {"task_id": "t"}, context=context).outputs["task"]
        task = tick_behavior(behavior("SetupMTCCurrentState"), {"task": task}, context=context).outputs[
            "task"
        ]
        setup = tick_behavior(
            behavior("SetupMTCPlanToRobotState"),
            {"task": task, "joint_state": goal, **ports},
            context=context,
        )
        assert setup.status == NodeStatus.SUCCESS, setup.toasts
        stage = setup.outputs["task"].stages[-1]
        run = tick_behavior(
            behavior("PlanMTCTask"), {"task": setup.outputs["task"]}, context=context, timeout=60
        )
        assert run.status == NodeStatus.SUCCESS, run.toasts
        return stage, run.outputs["solution"].sub_trajectories[0].trajectory

    stage, fast = plan()
    ports = {
        "velocity_scale_factor": 0.25,
        "acceleration_scale_factor": 0.5,
        "link_padding": 0.02,
        "trajectory_sampling_rate": 50,
        "max_iterations": 300,
        "seed": 7,
    }
    stage, slow = plan(**ports)
    motion = stage.motion
    assert (motion.velocity_scale, motion.acceleration_scale, motion.link_padding) == (0.25, 0.5, 0.02)
    assert (motion.sample_period, motion.max_iterations, motion.seed) == (0.02, 300, 7)
    assert slow.duration > 2.0 * fast.duration  # a quarter of the speed limits
    assert np.all(np.abs(np.diff(slow.times) - 0.02) < 0.002)  # 50 points a second
    task = tick_behavior(behavior("InitializeMTCTask"), {"task_id": "t"}, context=context).outputs["task"]
    bad = tick_behavior(
        behavior("SetupMTCPlanToRobotState"),
        {"task": task, "joint_state": goal, "velocity_scale_factor": 1.5},
        context=context,
    )
    assert bad.status == NodeStatus.FAILURE and "(0, 1]" in bad.toasts[-1]


# -- SavePoseStampedToYaml.namespace ----------------------------------------------------------------------


def test_namespaced_poses_collect_in_one_file(
    behavior: Any, node: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    offline = BehaviorContext(node)
    save = behavior("SavePoseStampedToYaml")

    def pose(x: float) -> Any:
        return from_dict(
            "geometry_msgs/msg/PoseStamped", {"header": {"frame_id": "tag"}, "pose": {"position": {"x": x}}}
        )

    for run, x in ((1, 0.1), (2, 0.2)):
        result = tick_behavior(
            save,
            {"message": pose(x), "yaml_filename": "runs", "namespace": run, "overwrite": False},
            context=offline,
        )
        assert result.status == NodeStatus.SUCCESS, result.toasts
    saved = yaml.safe_load((tmp_path / "runs.yaml").read_text())
    assert list(saved) == ["1", "2"]
    assert saved["2"]["pose"]["position"]["x"] == 0.2 and saved["1"]["header"]["frame_id"] == "tag"
    # the same namespace again: kept unless overwrite, as a file is
    again = tick_behavior(
        save,
        {"message": pose(0.3), "yaml_filename": "runs", "namespace": 1, "overwrite": False},
        context=offline,
    )
    assert again.status == NodeStatus.SUCCESS and "saving to runs_" in again.toasts[-1]
    assert yaml.safe_load((tmp_path / "runs.yaml").read_text())["1"]["pose"]["position"]["x"] == 0.1
    tick_behavior(
        save,
        {"message": pose(0.3), "yaml_filename": "runs", "namespace": 1, "overwrite": True},
        context=offline,
    )
    replaced = yaml.safe_load((tmp_path / "runs.yaml").read_text())
    assert replaced["1"]["pose"]["position"]["x"] == 0.3 and replaced["2"]["pose"]["position"]["x"] == 0.2


# -- MergePointClouds.icp_* -------------------------------------------------------------------------------


def _cloud(points: np.ndarray) -> Any:
    from kinema.interfaces import load_interfaces
    from kinema.perception import PointCloud
    from kinema.perception.ros_messages import to_point_cloud2

    return to_point_cloud2(PointCloud(points, frame_id="world"), load_interfaces().typestore.types)


def test_merge_point_clouds_aligns_with_the_icp_settings_given(
    behavior: Any, context: BehaviorContext
) -> None:
    from kinema.perception.ros_messages import from_point_cloud2

    rng = np.random.default_rng(4)
    # a corner of three walls, seen twice, the second view 2 cm off
    faces = [rng.uniform(0, 0.3, (1500, 3)) * mask for mask in ([1, 1, 0], [1, 0, 1], [0, 1, 1])]
    shape = np.vstack(faces)
    views = [_cloud(shape), _cloud(shape + np.array([0.02, 0.0, 0.0]))]

    def merged_views(clouds: list[Any], **ports: Any) -> Any:
        run = tick_behavior(
            behavior("MergePointClouds"),
            {"point_clouds": clouds, "grid_resolution_meters": 0.01, "align_point_clouds": True, **ports},
            context=context,
        )
        assert run.status == NodeStatus.SUCCESS, run.toasts
        return run, len(from_point_cloud2(run.outputs["merged_cloud"]))

    _, single = merged_views(views[:1], align_point_clouds=False)
    _, aligned = merged_views(views, icp_correspondence_distance=0.05, icp_max_iterations=30)
    # pairs must be within 1 mm: ICP hardly moves the second view
    _, unaligned = merged_views(views, icp_correspondence_distance=0.001, icp_max_iterations=30)
    assert aligned < 1.2 * single < unaligned  # aligned, the two views fill the same voxels
    bad = tick_behavior(
        behavior("MergePointClouds"),
        {"point_clouds": views, "align_point_clouds": True, "icp_max_iterations": 0},
        context=context,
    )
    assert bad.status == NodeStatus.FAILURE and "port [icp_max_iterations]" in bad.toasts[-1]


# -- PlanCartesianPath.{tip_link, trajectory_sampling_rate} -----------------------------------------------


def test_plan_cartesian_path_moves_the_tip_link_named_at_the_rate_asked(
    behavior: Any, context: BehaviorContext, at_home: None, lab_sim_model: Any
) -> None:
    from kinema.motion import fk

    start = fk(lab_sim_model, _q(lab_sim_model, HOME), "tool0")
    target = from_dict(
        "geometry_msgs/msg/PoseStamped",
        {"header": {"frame_id": "tool0"}, "pose": {"position": {"z": 0.05}, "orientation": {"w": 1.0}}},
    )
    run = tick_behavior(
        behavior("PlanCartesianPath"),
        {"path": [target], "tip_link": "tool0", "trajectory_sampling_rate": 40},
        context=context,
        timeout=30.0,
    )
    assert run.status == NodeStatus.SUCCESS, run.toasts
    trajectory = run.outputs["joint_trajectory_msg"]
    end = lab_sim_model.configuration(
        dict(zip(trajectory.joint_names, trajectory.points[-1].positions, strict=True))
    )
    np.testing.assert_allclose(
        fk(lab_sim_model, end, "tool0")[:3, 3], (start @ [0, 0, 0.05, 1])[:3], atol=2e-3
    )
    steps = np.diff([_seconds(p.time_from_start) for p in trajectory.points])
    assert np.all(np.abs(steps - 0.025) < 0.0025)  # 40 points a second
    clash = tick_behavior(
        behavior("PlanCartesianPath"),
        {"path": [target], "tip_link": "tool0", "tip_links": ["grasp_link"]},
        context=context,
    )
    assert clash.status == NodeStatus.FAILURE and "give one of the two" in clash.toasts[-1]
