"""With a simulator, time-based nodes follow /clock: frozen sim time holds a Sleep, fast sim time ends it."""

from __future__ import annotations

import time
from typing import Any


def test_sleep_follows_the_simulation_clock(sim_agent: Any) -> None:
    from kinema.sdk import ObjectiveClient, ObjectiveStatus

    with ObjectiveClient(sim_agent.endpoint, timeout=10) as client:
        clock = client.node.create_publisher("rosgraph_msgs/msg/Clock", "/clock")
        handle = client.start("Short Sleep")  # Sleep msec=200, in sim time
        deadline = time.monotonic() + 30.0
        while client.status().status is not ObjectiveStatus.RUNNING and time.monotonic() < deadline:
            time.sleep(0.05)
        assert client.status().status is ObjectiveStatus.RUNNING, client.status()
        time.sleep(0.6)  # three times the sleep in wall time, while the simulation does not move
        assert not handle.done
        assert client.status().status is ObjectiveStatus.RUNNING
        finished_at_sim_s = None
        step = 0
        deadline = time.monotonic() + 30.0  # bounds a real failure only: the steps stop once it ends
        while time.monotonic() < deadline:
            step += 1
            # 50 ms of sim time per message: a simulation running 10x faster than real time
            clock.publish({"clock": {"sec": step // 20, "nanosec": (step % 20) * 50_000_000}})
            if handle.done:
                finished_at_sim_s = step * 0.05
                break
            time.sleep(0.005)
        assert handle.result(5).succeeded
        # It ended because simulated time advanced (not wall time: that had passed before, above).
        assert finished_at_sim_s is not None and finished_at_sim_s >= 0.2, finished_at_sim_s
