"""A waypoint saved in a config based on lab_sim lands in that config's package, never in lab_sim's."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import pytest
import yaml

from kinema.drivers.mujoco import names as driver_names
from kinema.resources import bundled_dir
from kinema.runtime import names

LAB_SIM_WAYPOINTS = bundled_dir("configs") / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml"


def test_saving_a_waypoint_writes_the_derived_package_and_says_so(
    derived_config_agent: Any, tmp_path: Path
) -> None:
    from kinema.transport import Node, open_session

    shipped = LAB_SIM_WAYPOINTS.read_bytes()
    copy = tmp_path / "ws" / "src" / "my_cell" / "waypoints" / "lab_sim_waypoints.yaml"
    with open_session(derived_config_agent.endpoint) as session:
        node = Node(session, "waypoint_user")
        toasts: list[str] = []
        node.create_subscription(names.LOG_TYPE, names.LOG, lambda message: toasts.append(message.message))
        get = node.create_client(names.GET_WAYPOINTS_TYPE, names.GET_WAYPOINTS)
        edit = node.create_client(names.EDIT_WAYPOINTS_TYPE, names.EDIT_WAYPOINTS)
        inherited = [w.name for w in get.call({}, timeout=10).waypoints]
        assert inherited and "Look at Table" in inherited, inherited
        joints = node.create_publisher(driver_names.JOINT_STATES_TYPE, driver_names.JOINT_STATES_TOPIC)
        deadline = time.monotonic() + 15
        while True:
            joints.publish({"name": ["linear_rail_joint"], "position": [0.3]})
            saved = edit.call({"operation": 0, "waypoint_name": "My Spot"}, timeout=10)
            if saved.status.success or time.monotonic() > deadline:
                break
            time.sleep(0.05)
        assert saved.status.success, saved.status.error_message
        assert [w.name for w in get.call({}, timeout=10).waypoints] == [*inherited, "My Spot"]
        deadline = time.monotonic() + 10
        while not any("saved waypoints go to" in toast for toast in toasts) and time.monotonic() < deadline:
            time.sleep(0.05)
    assert LAB_SIM_WAYPOINTS.read_bytes() == shipped
    assert [item["name"] for item in yaml.safe_load(copy.read_text())] == [*inherited, "My Spot"]
    assert any(str(copy) in toast for toast in toasts), toasts
    assert "saved waypoints go to" in derived_config_agent.log_file.read_text()


def test_the_waypoint_verbs_save_list_rename_and_erase_with_the_configs_group(
    derived_config_agent: Any, tmp_path: Path, capsys: Any
) -> None:
    """`kinema waypoint ...` without the UI; a waypoint saved without a group is for the config's planning
    group (the UI's save sends none; the Waypoints tab then showed no group)."""
    from kinema.cli.main import main
    from kinema.transport import Node, open_session

    endpoint = derived_config_agent.endpoint

    def run(*args: str) -> tuple[int, str]:
        code = main(["waypoint", *args, "--connect", endpoint, "--timeout", "10"])
        captured = capsys.readouterr()
        return code, captured.out + captured.err

    with open_session(endpoint) as session:
        joints = Node(session, "joints").create_publisher(
            driver_names.JOINT_STATES_TYPE, driver_names.JOINT_STATES_TOPIC
        )
        deadline = time.monotonic() + 15
        while True:
            joints.publish({"name": ["linear_rail_joint", "elbow_joint"], "position": [0.3, 1.25]})
            code, output = run("save", "Bench Spot")
            if code == 0 or time.monotonic() > deadline:
                break
            time.sleep(0.1)
    assert code == 0, output
    assert "saved waypoint 'Bench Spot' (manipulator): linear_rail_joint=0.3, elbow_joint=1.25" in output
    code, output = run("list")
    assert code == 0 and any(
        line.split()[:3] == ["Bench", "Spot", "manipulator"] for line in output.splitlines()
    ), output
    # A group the robot does not have is refused, naming the robot's.
    code, output = run("save", "Elsewhere", "-g", "manipulater")
    assert code == 1 and "'manipulater' is no planning group" in output, output
    assert "did you mean 'manipulator'" in output, output
    assert run("rename", "Bench Spot", "Bench")[0] == 0
    code, output = run("erase", "Bench Spot")
    assert code == 1 and "did you mean 'Bench'" in output, output
    code, output = run("erase", "Bench")
    assert code == 0 and "it was linear_rail_joint=0.3, elbow_joint=1.25" in output, output
    code, output = run("list", "--json")
    assert "Bench" not in output and "Look at Table" in output
    # -c names what the runtime must serve: another config's waypoints are not listed as if they were its.
    code, output = run("list", "-c", "lab_sim")
    assert code == 1 and "serves config my_cell, not lab_sim" in output, output


@pytest.mark.parametrize("derived_config_agent", [True], indirect=True, ids=["watching"])
def test_an_edited_config_yaml_is_said_to_need_a_restart(derived_config_agent: Any, tmp_path: Path) -> None:
    """Objective files reload while the runtime runs; config.yaml does not: a user who changed
    robot.gripper saw the old values at work and nothing saying why."""
    from kinema.transport import Node, open_session

    config = tmp_path / "ws" / "src" / "my_cell" / "config" / "config.yaml"
    with open_session(derived_config_agent.endpoint) as session:
        toasts: list[str] = []
        Node(session, "watcher").create_subscription(
            names.LOG_TYPE, names.LOG, lambda message: toasts.append(message.message)
        )
        time.sleep(0.5)  # the watcher and the subscription settle
        config.write_text(config.read_text() + "\nrobot:\n  tool_frame: grasp_link\n")
        deadline = time.monotonic() + 15
        while not any("changed: this runtime keeps the config it started with" in t for t in toasts):
            assert time.monotonic() < deadline, toasts
            time.sleep(0.05)
    (notice,) = [t for t in toasts if "keeps the config" in t]
    assert str(config) in notice and "kinema run -c my_cell" in notice
    assert "keeps the config it started with" in derived_config_agent.log_file.read_text()
    # An objective such an edit adds (a new behavior package's library) is unknown until the restart, and
    # its refusal says so, not only the run's terminal.
    from kinema.sdk import ObjectiveClient

    with ObjectiveClient(derived_config_agent.endpoint, timeout=10) as client:
        refused = client.execute("UrTools Example")
    assert refused.failed and "unknown objective 'UrTools Example'" in refused.error_message
    assert "note: " in refused.error_message and "kinema run -c my_cell" in refused.error_message
