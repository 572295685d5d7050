"""`kinema waypoint list` with no runtime running lists the selected config's waypoints file (said so)."""

from __future__ import annotations

import pytest

from kinema.cli.main import main
from kinema.transport import free_endpoint


def test_waypoint_list_without_a_runtime_reads_the_configs_file(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["waypoint", "list", "-c", "lab_sim", "--connect", free_endpoint(), "--timeout", "1"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "note: no runtime answered; the waypoints of config lab_sim in" in captured.err
    assert "lab_sim_waypoints.yaml" in captured.err
    names = [line[2:].split("  ")[0] for line in captured.out.splitlines()]
    assert "Look at Table" in names and "3 Waypoint Pick Pose" in names, captured.out
