"""MoveIt Pro's admittance objectives, unchanged, on Kinema's lab_sim headless at max sim speed.

"Push Button With a Trajectory" moves to "VFC Start" on the admittance controller, zeroes the wrist
sensor (``/joint_trajectory_admittance_controller/zero_fts/tool0``), reads push_button_admittance_params.yaml
(compliant along grasp_link's z only, 180 N/m) and runs an 11 cm straight-line push along grasp_link's z
with it. "Stationary Admittance" holds the arm at "Home" for 10 s, compliant on every axis (40 N/m). The
tests push the tool (MuJoCo's ``xfrc_applied``, at grasp_site) while the compliant trajectory runs and
watch where it goes.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import numpy as np
import pytest
from lab_sim_library_cell import LibraryCell

pytestmark = pytest.mark.slow

ADMITTANCE_CONTROLLER = "joint_trajectory_admittance_controller"


class _Pusher:
    """Pushes grasp_site with ``force`` (N, world frame) whenever the admittance controller runs a
    compliant goal, and records grasp_site's position then."""

    def __init__(self, cell: LibraryCell, force: tuple[float, float, float]) -> None:
        driver = cell.driver
        self._driver = driver
        self._controller = driver.controller_manager.get(ADMITTANCE_CONTROLLER)
        self._site = int(driver.model.site("grasp_site").id)
        self._body = int(driver.model.body("grasp_link").id)
        self._force = np.asarray(force, dtype=float)
        self.compliant: list[np.ndarray] = []  # grasp_site while a compliant goal runs
        self.times: list[float] = []  # and the sim time
        self.last = np.zeros(3)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _step(self) -> None:
        data = self._driver.data
        position = data.site_xpos[self._site].copy()
        self.last = position
        if self._controller.compliant:
            # Applied at grasp_site: xfrc_applied acts at the body's centre of mass, so add the moment.
            arm = position - data.xipos[self._body]
            data.xfrc_applied[self._body] = np.concatenate((self._force, np.cross(arm, self._force)))
            self.compliant.append(position)
            self.times.append(float(data.time))
        else:
            data.xfrc_applied[self._body] = 0.0

    def _run(self) -> None:
        while not self._stop.is_set():
            self._driver.simulation.call(self._step)
            time.sleep(0.001)

    def __enter__(self) -> _Pusher:
        self._thread.start()
        return self

    @property
    def compliant_for(self) -> float:
        """Sim seconds the compliant goal ran (between the first and last sample)."""
        return self.times[-1] - self.times[0] if self.times else 0.0

    def __exit__(self, *_exc: object) -> None:
        self._stop.set()
        self._thread.join()
        body = self._body
        self._driver.simulation.call(lambda: self._driver.data.xfrc_applied.__setitem__(body, 0.0))


def _spring(force: float, stiffness: float, damping: float, seconds: float) -> float:
    """How far an overdamped spring (mass negligible) moves under ``force`` in ``seconds``, m."""
    return force / stiffness * (1.0 - np.exp(-seconds * stiffness / damping))


def _run(cell: LibraryCell, objective: str, force: tuple[float, float, float]) -> tuple[Any, _Pusher]:
    with _Pusher(cell, force) as pusher:
        result = cell.client.execute(objective, timeout=240.0)
    return result, pusher


def test_push_button_with_a_trajectory_pushes_11_cm_and_gives_way_along_z(library_cell: LibraryCell) -> None:
    result, free = _run(library_cell, "Push Button With a Trajectory", (0.0, 0.0, 0.0))
    assert result.succeeded, result
    # Nothing in the way: the straight line went 11 cm down grasp_link's z (world down at VFC Start).
    assert free.last[2] == pytest.approx(0.62 - 0.11, abs=0.006), free.last
    # Again, pushed up with 20 N while the compliant trajectory runs. Compliant along z (0.1 kg, 180 N/m,
    # damping ratio 100: 849 N s/m), the tool gives way upward as that spring does over the push (about
    # 1.2 cm in the 0.54 s the push takes); x and y are rigid and end about where they did.
    result, pushed = _run(library_cell, "Push Button With a Trajectory", (0.0, 0.0, 20.0))
    assert result.succeeded, result
    assert pushed.compliant, "the admittance controller never ran a compliant goal"
    gave = pushed.last - free.last
    expected = _spring(20.0, 180.0, 2 * 100 * np.sqrt(0.1 * 180.0), pushed.compliant_for)
    # The pusher is a thread polling the simulation: on a loaded machine it takes the force off a while
    # after the compliant goal ended, and the rigid servos then give a little more (1.96 cm was seen at
    # load 20), so the bound above the spring's is wider than the one below.
    assert 0.7 * expected <= gave[2] <= 2.0 * expected, (gave, expected, pushed.compliant_for)
    assert gave[2] > 0.005, gave
    assert np.abs(gave[:2]).max() < 0.3 * gave[2], gave


def test_stationary_admittance_holds_the_arm_and_lets_a_push_move_it(library_cell: LibraryCell) -> None:
    # Unpushed, the compliant arm stays where "Home" put it: the sensor reads only the tool's weight, which
    # the controller does not take for a push.
    result, still = _run(library_cell, "Stationary Admittance", (0.0, 0.0, 0.0))
    assert result.succeeded, result
    assert len(still.compliant) > 10, "the admittance controller never ran a compliant goal"
    drift = np.abs(still.compliant[-1] - still.compliant[0]).max()
    assert drift < 0.002, drift
    home = still.last.copy()
    # Pushed sideways with 20 N while the 10 s stationary trajectory runs: a 4 kg, 40 N/m spring damped at
    # 160 times critical (4048 N s/m) moves about 20/40 * (1 - exp(-10 * 40 / 4048)) = 4.7 cm along the push.
    result, pushed = _run(library_cell, "Stationary Admittance", (0.0, 20.0, 0.0))
    assert result.succeeded, result
    assert pushed.compliant_for > 9.0, pushed.compliant_for
    moved = pushed.last - home
    expected = _spring(20.0, 40.0, 2 * 160 * np.sqrt(4 * 40.0), pushed.compliant_for)
    assert 0.75 * expected <= moved[1] <= 1.6 * expected, (moved, expected)  # see the push test above
    assert abs(moved[0]) < 0.01 and abs(moved[2]) < 0.01, moved
