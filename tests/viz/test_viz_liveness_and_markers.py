"""The runtime-lost banner and marker lifetimes, on a fake clock."""

from __future__ import annotations

from types import SimpleNamespace as NS

import numpy as np

from kinema.viz.liveness import RuntimeLiveness
from kinema.viz.markers import MarkerBoard


class FakeClock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_banner_when_runtime_goes_away_and_clears_when_it_returns() -> None:
    clock = FakeClock()
    live = RuntimeLiveness("tcp/127.0.0.1:1", clock=clock)
    live.heard_heartbeat()
    live.heard_driver()
    assert live.verdict().level == "ok"
    clock.now += 2.5
    verdict = live.verdict()
    assert verdict.level == "error" and "not reachable" in verdict.banner
    live.heard_heartbeat()
    live.heard_driver()
    assert live.verdict().banner == ""


def test_driver_stopping_alone_is_a_warning() -> None:
    clock = FakeClock()
    live = RuntimeLiveness("e", clock=clock)
    live.heard_driver()
    clock.now += 3
    live.heard_heartbeat()
    verdict = live.verdict()
    assert verdict.level == "warning" and "driver stopped" in verdict.banner


def _marker(ns: str, marker_id: int, lifetime: float, action: int = 0) -> NS:
    point = NS(x=0.0, y=0.0, z=0.0)
    return NS(
        ns=ns,
        id=marker_id,
        type=0,
        action=action,
        pose=NS(position=point, orientation=NS(x=0.0, y=0.0, z=0.0, w=1.0)),
        scale=NS(x=0.01, y=0.02, z=0.03),
        color=NS(r=1.0, g=0.0, b=0.0, a=1.0),
        colors=[],
        points=[point, NS(x=0.1, y=0.0, z=0.0)],
        lifetime=NS(sec=int(lifetime), nanosec=int((lifetime % 1) * 1e9)),
    )


def test_marker_lifetime_is_honoured_and_zero_keeps_it() -> None:
    clock = FakeClock()
    board = MarkerBoard("/m", clock=clock)
    drawn = board.update(_marker("pose", 0, 1.5), np.eye(4))
    assert [c[0] for c in drawn].count("set_object") == 2  # arrow shaft and head
    board.update(_marker("kept", 0, 0.0), np.eye(4))
    clock.now += 1.0
    assert board.expire() == []
    clock.now += 1.0
    expired = board.expire()
    assert [(c[0], c[1]) for c in expired] == [("delete", "/m/pose/0")]
    assert board.keys == [("kept", 0)]


def test_same_key_replaces_and_delete_removes() -> None:
    board = MarkerBoard("/m", clock=FakeClock())
    board.update(_marker("a", 1, 0.0), np.eye(4))
    replaced = board.update(_marker("a", 1, 0.0), np.eye(4))
    assert replaced[0][:2] == ("delete", "/m/a/1")
    removed = board.update(_marker("a", 1, 0.0, action=2), np.eye(4))
    assert [c[:2] for c in removed] == [("delete", "/m/a/1")] and board.keys == []


def test_a_marker_with_a_nan_orientation_is_skipped_and_the_rest_still_drawn() -> None:
    board = MarkerBoard("/m", clock=FakeClock())
    broken = _marker("bad", 0, 0.0)
    broken.pose.orientation = NS(x=float("nan"), y=0.0, z=0.0, w=1.0)
    assert board.update(broken, np.eye(4)) == [] and board.keys == []
    unset = _marker("unset", 0, 0.0)
    unset.pose.orientation = NS(x=0.0, y=0.0, z=0.0, w=0.0)  # never filled in: the identity, as in RViz
    assert [c[0] for c in board.update(unset, np.eye(4))].count("set_object") == 2
