"""docs/own-robot.md, run as a reader would: the Panda of example-robot-data from its URDF to a pick.

Every console block runs in a fresh folder (see test_tutorial's Reader), and the cube the page puts on the
table must end at least 5 cm higher after "Pick Cube", as `kinema sim bodies` reports it from the simulator.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from console_blocks import parse_steps
from test_tutorial import Reader, _run_logs

from kinema.config.robot_files import PackageIndex

DOCUMENT = Path(__file__).resolve().parents[2] / "docs" / "own-robot.md"


def _cube_height(output: str) -> float:
    for line in output.splitlines():
        words = line.split()
        if words and words[0] == "cube":
            return float(words[3])
    raise AssertionError(f"`kinema sim bodies` did not list the cube:\n{output}")


def test_the_page_shows_the_generator_and_the_pick() -> None:
    steps = parse_steps(DOCUMENT.read_text(encoding="utf-8"))
    commands = [c.text for s in steps for c in s.commands]
    assert any("--from-urdf" in c for c in commands)
    assert any(c.startswith('kinema objective run "Pick Cube"') for c in commands)
    assert {s.path for s in steps if s.kind == "file"} == {
        "src/panda_cell/description/objects.xml",
        "src/panda_cell/objectives/pick_cube.xml",
    }


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_the_panda_picks_the_cube_as_the_page_says(
    tmp_path: Path, request: pytest.FixtureRequest, show_on_failure: Any
) -> None:
    if PackageIndex().find("example-robot-data") is None:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data, in the test extra)")
    steps = parse_steps(DOCUMENT.read_text(encoding="utf-8"))
    reader = Reader(tmp_path, "own-robot.md")
    show_on_failure(request.node, "the runtimes' logs", lambda: _run_logs(tmp_path))
    reader.follow(steps)
    heights = [_cube_height(output) for text, output in reader.outputs if text == "kinema sim bodies"]
    assert len(heights) == 2, reader.outputs
    before, after = heights
    assert before == pytest.approx(0.02, abs=0.005), f"the cube starts at z={before:.3f} m, not on the table"
    assert after - before >= 0.05, f"the cube rose {after - before:.3f} m (from {before:.3f} to {after:.3f})"
