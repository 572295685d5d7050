"""Blackboard values written by the fast flow writer read exactly as yaml.safe_dump writes them."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from kinema.runtime.blackboard_text import _preview, render_value
from kinema.transport import from_dict


def _yaml(value: object) -> str:
    """What rendering gave before the fast writer: YAML's text of the value's preview."""
    return yaml.safe_dump(_preview(value), default_flow_style=True, width=1 << 30).strip()


@pytest.mark.parametrize(
    "value",
    [
        {"b": 1, "a": [1.5, -0.0, 1e20, 1e-7, float("nan"), float("inf"), -float("inf"), 3]},
        ["yes", "no", "null", "~", "true", "1.5", "0x1F", "2024-01-01", "on", "", "-", "a: b", "a #b"],
        ["a,b", "[x]", "{y}", "it's", 'say "hi"', "?", ":", "&anchor", "*alias", "!tag", "%", "@", "`"],
        {"naïve": "é", "key with spaces": {"nested": [[], {}, None, True, False]}},
        [{"positions": [0.1, 0.2], "time_from_start": {"nanosec": 5, "sec": 1}} for _ in range(3)],
    ],
)
def test_plain_data_renders_as_yaml_writes_it(value: object) -> None:
    assert render_value(value) == _yaml(value)


@pytest.mark.parametrize(
    "value",
    [
        {"": 1},  # YAML writes an empty key as a complex key
        {"k" * 200: 1},  # and a long one
        ["line\nbreak"],
        [1, 2, "x" * 300],
        {1: "int key"},
        [{"positions": [0.1, 0.2]}] * 3,  # one dict three times (the preview copies it)
    ],
)
def test_values_the_fast_writer_leaves_to_yaml_render_as_before(value: object) -> None:
    assert render_value(value) == _yaml(value)


def test_a_trajectory_message_renders_its_first_points_as_yaml_would() -> None:
    points = [
        {"positions": np.full(7, 0.1 * i), "time_from_start": {"sec": i, "nanosec": 250_000_000}}
        for i in range(40)
    ]
    message = from_dict(
        "trajectory_msgs/msg/JointTrajectory", {"joint_names": list("abcdefg"), "points": points}
    )
    text = render_value(message)
    assert text.startswith("{header: {frame_id: '', stamp: {nanosec: 0, sec: 0}}, joint_names: [a, b,")
    assert "positions: [0.30000000000000004, 0.30000000000000004," in text
    assert "time_from_start: {nanosec: 250000000, sec: 3}" in text
