"""MoveIt Pro's velocity-force objective, unchanged, on Kinema's lab_sim headless at max sim speed.

``move_with_velocity_and_force.xml`` ("Push Button") moves to "VFC Start" with the admittance trajectory
controller, switches to the velocity-force controller, zeroes the wrist sensor, drives the gripper down at
5 cm/s until ``ForceExceedsThreshold`` sees more than 20 N, relaxes the contact ("Force Relaxation", a
SubTree passing a number literal on to Timeout's unsigned ``msec``) and moves to "Look at Table". The
test watches the simulator itself: where the fingertips went, what the sensor felt, which controllers ran.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import numpy as np
import pytest
from lab_sim_library_cell import LibraryCell, wait_for

pytestmark = pytest.mark.slow

TABLE_TOP = 0.474  # lab_sim's table top (world z, m)
# The finger pads reach 2 cm below grasp_link: grasp_link's height when they touch the table.
GRASP_AT_CONTACT = TABLE_TOP + 0.02


class _Sampler:
    """Samples the simulation (grasp_site height, the sensor's force) every few ms of wall time."""

    def __init__(self, cell: LibraryCell) -> None:
        driver = cell.driver
        self._driver = driver
        self._site = int(driver.model.site("grasp_site").id)
        self.samples: list[tuple[float, float, np.ndarray]] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _sample(self) -> tuple[float, float, np.ndarray]:
        data = self._driver.data
        force = np.array(data.sensor("tcp_fts_sensor_force").data)
        return float(data.time), float(data.site_xpos[self._site][2]), force

    def _run(self) -> None:
        while not self._stop.is_set():
            self.samples.append(self._driver.simulation.call(self._sample))
            time.sleep(0.002)

    def __enter__(self) -> _Sampler:
        self._thread.start()
        return self

    def __exit__(self, *_exc: object) -> None:
        self._stop.set()
        self._thread.join()


def _controllers(cell: LibraryCell) -> dict[str, str]:
    client = cell.node.create_client(
        "controller_manager_msgs/srv/ListControllers", "/controller_manager/list_controllers"
    )
    reply = client.call({}, timeout=10.0)
    return {str(c.name): str(c.state) for c in reply.controller}


def test_push_button_presses_the_table_until_the_force_threshold_then_relaxes(
    library_cell: LibraryCell,
) -> None:
    wrenches = library_cell.listen(
        "geometry_msgs/msg/WrenchStamped", "/force_torque_sensor_broadcaster/wrench"
    )
    wait_for(lambda: wrenches, 10.0, "the wrist sensor's wrench on /force_torque_sensor_broadcaster/wrench")
    assert wrenches[-1].header.frame_id == "tool0"
    with _Sampler(library_cell) as sampler:
        result = library_cell.client.execute("Push Button", timeout=240.0)
    assert result.succeeded, result
    times = np.array([s[0] for s in sampler.samples])
    heights = np.array([s[1] for s in sampler.samples])
    forces = np.array([s[2] for s in sampler.samples])
    lowest = int(np.argmin(heights))
    # The gripper went down until its fingers pressed the table, and not through it.
    assert heights[lowest] == pytest.approx(GRASP_AT_CONTACT, abs=0.006), heights[lowest]
    # The sensor felt the contact: its force changed by more than the objective's 20 N threshold...
    resting = forces[0]
    change = np.linalg.norm(forces - resting, axis=1)
    assert change.max() > 20.0, change.max()
    first_contact = int(np.argmax(change > 20.0))
    # ... and the push stopped there: within 0.2 s of sim time of the threshold (the controller's command
    # timeout and a few publish periods) the gripper rose no lower than it was.
    after = (times > times[first_contact]) & (times < times[first_contact] + 0.3)
    assert heights[after].min() >= heights[first_contact] - 0.01
    # Force Relaxation let go of the press: before leaving, the contact force fell back near zero.
    leaving = int(np.argmax((times > times[lowest]) & (heights > GRASP_AT_CONTACT + 0.03)))
    relaxed = change[max(first_contact, leaving - 20) : leaving]
    assert relaxed.size and relaxed.min() < 5.0, relaxed
    # Finally "Look at Table" ran on the admittance controller, which is active again.
    states = _controllers(library_cell)
    assert states["joint_trajectory_admittance_controller"] == "active", states
    assert states["velocity_force_controller"] == "inactive", states
    assert heights[-1] > GRASP_AT_CONTACT + 0.1


def test_force_exceeds_threshold_fails_naming_a_silent_topic(library_cell: LibraryCell) -> None:
    xml = """
<root BTCPP_format="4" main_tree_to_execute="Silent Sensor">
  <BehaviorTree ID="Silent Sensor">
    <Action ID="ForceExceedsThreshold" wrench_topic_name="/no_sensor/wrench" force_threshold="20"
            minimum_consecutive_wrench_values="5" wrench_frame_name="tool0" hand_frame_name="grasp_link"/>
  </BehaviorTree>
</root>"""
    result: Any = library_cell.client.do_xml(xml, timeout=60.0)
    assert result.failed, result
    assert "no wrench on /no_sensor/wrench" in result.error_message, result
