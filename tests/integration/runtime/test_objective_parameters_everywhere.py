"""One list of an objective's parameters: `kinema objective show --json`, the SDK and the TUI's form agree."""

from __future__ import annotations

import json
import subprocess
import sys
from typing import Any

import pytest

OBJECTIVES = ["Move to Waypoint", "Open Gripper"]


def _cli_parameters(name: str) -> list[tuple[str, str, str, str | None]]:
    shown = subprocess.run(
        [sys.executable, "-m", "kinema", "objective", "show", name, "-c", "lab_sim", "--json"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert shown.returncode == 0, shown.stderr
    ports = json.loads(shown.stdout)["ports"]
    # The ObjectivePort message carries "" both for "no default" and for an empty default.
    return [
        (p["name"], p["direction"], p["type"], p["default"] or None)
        for p in ports
        if p["direction"] != "output"
    ]


@pytest.mark.parametrize("name", OBJECTIVES)
def test_cli_sdk_and_tui_list_the_same_parameters(lab_sim_agent: Any, name: str) -> None:
    from kinema.sdk import ObjectiveClient
    from kinema.tui.sdk_connection import _objective_summary

    expected = _cli_parameters(name)
    with ObjectiveClient(lab_sim_agent.endpoint, timeout=10) as client:
        sdk = [(p.name, p.direction, p.type_name, p.default) for p in client.parameters(name)]
        info = next(i for i in client.objectives() if i.name == name)
    assert sdk == expected
    # The TUI's override form is built from this summary's input/inout ports.
    summary = _objective_summary(info)
    tui = [
        (p.name, p.direction, p.type_name, p.default or None)
        for p in summary.ports
        if p.direction != "output"
    ]
    assert tui == expected
    if name == "Move to Waypoint":
        assert ("link_padding", "input", "double", "0.01") in expected


def test_sdk_parameters_of_an_unknown_objective(lab_sim_agent: Any) -> None:
    from kinema.errors import ObjectiveError
    from kinema.sdk import ObjectiveClient

    with ObjectiveClient(lab_sim_agent.endpoint, timeout=10) as client:
        # A name that is not there is the objective's error, not the transport's (it answered).
        with pytest.raises(ObjectiveError, match=r"no objective named 'Move to Waypont'.*Move to Waypoint"):
            client.parameters("Move to Waypont")
