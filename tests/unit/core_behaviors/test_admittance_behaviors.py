"""SetAdmittanceParameters (MoveIt Pro's YAML files into a message) and the admittance ports of
ExecuteTrajectory and ExecuteTrajectoryWithAdmittance."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import pytest
import yaml

from kinema.behaviors import BehaviorContext
from kinema.bt import NodeStatus
from kinema.testing import tick_behavior
from kinema.transport import from_dict

CORPUS = (
    Path(__file__).resolve().parents[3].parent / "shared" / "compat" / "moveit_pro" / "lab_sim" / "objectives"
)
PARAMETERS = "moveit_pro_controllers_msgs/msg/AdmittanceParameters"
ARM = ["linear_rail_joint", "shoulder_pan_joint"]


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An objectives folder: offline contexts (no config) resolve relative paths in the working directory."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.fixture
def offline(node: Any) -> BehaviorContext:
    return BehaviorContext(node)


def _corpus_file(name: str, folder: Path) -> Path:
    source = CORPUS / name
    if not source.is_file():
        pytest.skip(f"{source} (MoveIt Pro's lab_sim files) is not beside this checkout")
    return Path(shutil.copy(source, folder / name))


def _set(behavior: Any, context: BehaviorContext, name: str) -> Any:
    return tick_behavior(behavior("SetAdmittanceParameters"), {"config_file_name": name}, context=context)


def test_moveit_pros_push_button_parameters_load(
    behavior: Any, offline: BehaviorContext, folder: Path
) -> None:
    _corpus_file("push_button_admittance_params.yaml", folder)
    run = _set(behavior, offline, "push_button_admittance_params.yaml")
    assert run.status == NodeStatus.SUCCESS, run.toasts
    message = run.outputs["admittance_parameters_msg"]
    assert message.__msgtype__ == PARAMETERS
    assert (message.control_frame, message.end_effector_frame) == ("grasp_link", "grasp_link")
    axes = message.selected_axes
    assert [axes.x, axes.y, axes.z, axes.rx, axes.ry, axes.rz] == [False, False, True, False, False, False]
    assert (message.mass_position.z, message.stiffness_position.z) == (0.1, 180.0)
    assert (message.damping_ratio_position.z, message.joint_damping) == (100.0, 1.0)


def test_moveit_pros_stationary_parameters_load(
    behavior: Any, offline: BehaviorContext, folder: Path
) -> None:
    # The file repeats its keys at the top level; the SetAdmittanceParameters section is the one read.
    _corpus_file("stationary_admittance.yaml", folder)
    run = _set(behavior, offline, "stationary_admittance.yaml")
    assert run.status == NodeStatus.SUCCESS, run.toasts
    message = run.outputs["admittance_parameters_msg"]
    assert message.selected_axes.rz and message.selected_axes.x
    assert (message.mass_position.x, message.stiffness_position.y) == (4.0, 40.0)
    assert message.damping_ratio_position.z == 160.0  # the section's, not the top level's 80


def _parameters(**changes: Any) -> dict[str, Any]:
    vector = {"x": 1.0, "y": 1.0, "z": 1.0, "min": 0.0, "max": 100.0}
    admittance: dict[str, Any] = {
        "selected_axes": {a: True for a in ("x", "y", "z", "rx", "ry", "rz")},
        "mass_position": dict(vector),
        "mass_rotation": dict(vector),
        "stiffness_position": dict(vector),
        "stiffness_rotation": dict(vector),
        "damping_ratio_position": dict(vector),
        "damping_ratio_rotation": dict(vector),
        "joint_damping": {"value": 1.0, "min": 0.0, "max": 10.0},
    }
    admittance.update(changes)
    return {"SetAdmittanceParameters": {"control_frame": "grasp_link", "admittance": admittance}}


@pytest.mark.parametrize(
    ("changes", "expected"),
    [
        ({"stiffness_position": {"x": 500.0, "y": 1, "z": 1, "min": 0, "max": 100}}, "= 500 N/m is outside"),
        ({"stifness_position": {}}, "unknown key admittance.stifness_position"),
        ({"mass_rotation": {"x": 1, "y": 1}}, "admittance.mass_rotation lacks z"),
        ({"selected_axes": {"x": "yes"}}, "selected_axes must give each of x, y, z"),
        ({"joint_damping": {"value": "fast"}}, "joint_damping.value must be a number"),
    ],
)
def test_bad_parameter_files_fail_naming_the_key(
    behavior: Any, offline: BehaviorContext, folder: Path, changes: dict[str, Any], expected: str
) -> None:
    (folder / "params.yaml").write_text(yaml.safe_dump(_parameters(**changes)))
    run = _set(behavior, offline, "params.yaml")
    assert run.status == NodeStatus.FAILURE
    assert "port [config_file_name]" in run.toasts[-1] and expected in run.toasts[-1], run.toasts[-1]


def test_a_missing_file_names_where_it_looked(behavior: Any, offline: BehaviorContext, folder: Path) -> None:
    run = _set(behavior, offline, "nowhere.yaml")
    assert run.status == NodeStatus.FAILURE and "no such file" in run.toasts[-1], run.toasts


def _trajectory() -> Any:
    points = [{"positions": [0.0, 0.0], "time_from_start": {"sec": 1, "nanosec": 0}}]
    return from_dict("trajectory_msgs/msg/JointTrajectory", {"joint_names": ARM, "points": points})


@pytest.mark.parametrize("behavior_id", ["ExecuteTrajectory", "ExecuteTrajectoryWithAdmittance"])
@pytest.mark.parametrize(
    ("inputs", "expected"),
    [
        ({"absolute_force_torque_threshold": "45;45;45;10;10"}, "give six positive values"),
        ({"absolute_force_torque_threshold": "45;45;0;10;10;10"}, "give six positive values"),
        (
            {"admittance_parameters_msg": "stiff"},
            "not a moveit_pro_controllers_msgs/msg/AdmittanceParameters",
        ),
    ],
)
def test_bad_admittance_ports_fail_naming_the_port(
    behavior: Any, context: BehaviorContext, behavior_id: str, inputs: dict[str, Any], expected: str
) -> None:
    run = tick_behavior(
        behavior(behavior_id),
        {
            "joint_trajectory_msg": _trajectory(),
            "controller_action_name": "/arm/follow_joint_trajectory",
            **inputs,
        },
        context=context,
    )
    assert run.status == NodeStatus.FAILURE
    assert expected in run.toasts[-1], run.toasts


def test_parameters_naming_a_controller_that_is_no_admittance_controller_fail(
    behavior: Any, context: BehaviorContext
) -> None:
    parameters = from_dict(
        PARAMETERS, {"controller_name": "joint_trajectory_controller", "selected_axes": {"z": True}}
    )
    run = tick_behavior(
        behavior("ExecuteTrajectory"),
        {"joint_trajectory_msg": _trajectory(), "admittance_parameters_msg": parameters},
        context=context,
    )
    assert run.status == NodeStatus.FAILURE
    assert "controller_name 'joint_trajectory_controller'" in run.toasts[-1], run.toasts
    assert "admittance controllers: joint_trajectory_admittance_controller" in run.toasts[-1], run.toasts


def test_with_admittance_defaults_to_the_configs_admittance_controller(registry: Any, context: Any) -> None:
    from kinema.behaviors.cell_ports import resolve_cell_ports

    ports = resolve_cell_ports(registry["ExecuteTrajectoryWithAdmittance"].cls.provided_ports(), context.cell)
    action = next(p for p in ports if p.name == "controller_action_name")
    assert action.default == "/joint_trajectory_admittance_controller/follow_joint_trajectory"
