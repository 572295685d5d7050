"""Outcomes are honest: what died is named, and a run nobody cancelled never ends as a cancel."""

from __future__ import annotations

import subprocess
import sys
import time
from typing import Any

from kinema.runtime.error_codes import MoveItErrorCode
from kinema.runtime.objective_status import ObjectiveStatus

FAKE_DRIVER = """
import sys, time
from kinema.runtime.cell import DRIVER, declare_presence
from kinema.transport import open_session
session = open_session(sys.argv[1], mode="peer")
declare_presence(session, DRIVER, name="fake_arm", config="test")
print("declared", flush=True)
time.sleep(600)
"""


def test_a_driver_that_dies_mid_objective_ends_it_as_a_failure_naming_the_driver(fresh_agent: Any) -> None:
    from kinema.sdk import QuickClient

    agent = fresh_agent
    driver = subprocess.Popen(
        [sys.executable, "-c", FAKE_DRIVER, agent.endpoint], stdout=subprocess.PIPE, text=True
    )
    try:
        assert driver.stdout is not None and driver.stdout.readline().strip() == "declared"
        with QuickClient(agent.endpoint, timeout=10) as quick:
            run = quick.start("Forever")
            deadline = time.monotonic() + 10
            while quick.status() != (ObjectiveStatus.RUNNING, "Forever"):
                assert time.monotonic() < deadline, "the objective never ran"
                time.sleep(0.01)
            # The agent saw the driver's presence (history) before: kill it as a crash would.
            time.sleep(0.2)
            driver.kill()
            result = run.result()
        assert result.error_code == MoveItErrorCode.FAILURE, result
        assert "driver 'fake_arm'" in result.error_message and "went away" in result.error_message, result
    finally:
        driver.kill()
        driver.wait(10)


def test_a_stopping_agent_ends_the_running_objective_as_a_failure(fresh_agent: Any) -> None:
    from kinema.sdk import ObjectiveClient

    stopping = fresh_agent
    with ObjectiveClient(stopping.endpoint, timeout=10) as client:
        handle = client.start("Forever")
        deadline = time.monotonic() + 10
        while handle.status != "EXECUTING":
            assert time.monotonic() < deadline, handle.status
            time.sleep(0.01)
        stopping.process.terminate()
        result = handle.result(20)
    assert result.error_code == MoveItErrorCode.FAILURE and "the agent stopped" in result.error_message, (
        result
    )
