"""``kinema sim …`` against a running driver."""

from __future__ import annotations

import json
from collections.abc import Callable

import numpy as np
import pytest
from driver_harness import ARM, Sim

from kinema.cli.main import main


@pytest.fixture
def run(capsys: pytest.CaptureFixture[str]) -> Callable[..., tuple[int, str]]:
    """``run("sim", "bodies", ...)`` → exit code and everything printed (stdout, then stderr)."""

    def invoke(*args: str) -> tuple[int, str]:
        code = main(list(args))
        captured = capsys.readouterr()
        return code, captured.out + captured.err

    return invoke


def test_sim_bodies_prints_each_free_body_and_its_position(
    sim: Sim, router_endpoint: str, run: Callable[..., tuple[int, str]]
) -> None:
    code, output = run("sim", "bodies", "--connect", router_endpoint)
    assert code == 0, output
    (row,) = [line for line in output.splitlines() if line.startswith("cube")]
    assert [float(v) for v in row.split()[1:]] == pytest.approx([-0.30, 0.62, 0.499], abs=2e-3)


def test_sim_bodies_json(sim: Sim, router_endpoint: str, run: Callable[..., tuple[int, str]]) -> None:
    code, output = run("sim", "bodies", "--json", "--connect", router_endpoint)
    assert code == 0, output
    data = json.loads(output)
    assert data["sim_time"] > 0
    names = [b["name"] for b in data["bodies"]]
    assert names[0] == "cube" and "tag_block" in names, names
    assert data["bodies"][0]["position"] == pytest.approx([-0.30, 0.62, 0.499], abs=2e-3)
    assert len(data["bodies"][0]["orientation"]) == 4


def test_sim_keyframes_marks_the_initial_one(
    sim: Sim, router_endpoint: str, run: Callable[..., tuple[int, str]]
) -> None:
    code, output = run("sim", "keyframes", "--connect", router_endpoint)
    assert code == 0, output
    assert output.split("\n")[:2] == ["* default", "  home"]


def test_sim_set_joints_then_reset(
    sim: Sim, router_endpoint: str, run: Callable[..., tuple[int, str]]
) -> None:
    code, output = run(
        "sim", "set-joints", "elbow_joint=1.2", "shoulder_pan_joint=0.3", "--connect", router_endpoint
    )
    assert code == 0, output
    sim.settle(0.3)
    assert sim.joint_states.latest(("elbow_joint", "shoulder_pan_joint")) == pytest.approx(
        [1.2, 0.3], abs=2e-3
    )
    # `kinema sim joints` reads them back (what `set-joints` set, the arm's other joints where they were).
    code, output = run("sim", "joints", "--connect", router_endpoint)
    assert code == 0, output
    rows = {line.split()[0]: line.split()[1:] for line in output.splitlines()[1:]}
    assert float(rows["elbow_joint"][0]) == pytest.approx(1.2, abs=2e-3)
    assert float(rows["shoulder_pan_joint"][0]) == pytest.approx(0.3, abs=2e-3)
    code, output = run("sim", "joints", "--json", "--connect", router_endpoint)
    assert code == 0, output
    assert json.loads(output)["joints"]["elbow_joint"] == pytest.approx(1.2, abs=2e-3)
    code, output = run("sim", "reset", "--connect", router_endpoint)
    assert code == 0, output
    assert "default" in output
    sim.settle(0.3)
    np.testing.assert_allclose(sim.joint_states.latest(ARM), [0, 0, -2, 2, -1.5708, -1.5708, 0], atol=2e-3)


def test_sim_errors_are_one_line(sim: Sim, router_endpoint: str, run: Callable[..., tuple[int, str]]) -> None:
    code, output = run("sim", "set-joints", "elbow=1", "--connect", router_endpoint)
    assert code == 1
    assert output.startswith("error: ")
    assert "elbow_joint" in output
    code, output = run("sim", "reset", "homme", "--connect", router_endpoint)
    assert code == 1
    assert "home" in output
    code, output = run("sim", "set-joints", "elbow_joint", "--connect", router_endpoint)
    assert code == 2
    assert "JOINT=VALUE" in output
