"""The TUI's UI-free logic: tree outlines numbered like the engine, blackboard diffs, config rows, status."""

from __future__ import annotations

import pytest

from kinema.bt import BehaviorTreeFactory
from kinema.config import Workspace, resolve_config
from kinema.errors import ObjectiveError
from kinema.tui.blackboard_model import BlackboardDiff, BlackboardModel, row_key
from kinema.tui.config_view import config_rows, package_files
from kinema.tui.connection import BlackboardEntry, ClockSample, ConnectionChanged, ConnectionState, Heartbeat
from kinema.tui.runtime_status import RuntimeStatus
from kinema.tui.tree_outline import build_outline

NESTED_XML = """
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="top">
      <AlwaysSuccess/>
      <SubTree ID="Inner" name="first"/>
      <Fallback>
        <AlwaysFailure name="nope"/>
        <SubTree ID="Inner"/>
      </Fallback>
      <Action ID="AlwaysSuccess" name="done"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Inner">
    <Sequence>
      <Sleep msec="1"/>
      <Inverter><AlwaysFailure/></Inverter>
    </Sequence>
  </BehaviorTree>
</root>
"""


def test_outline_numbers_nodes_exactly_as_the_engine_builds_them() -> None:
    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(NESTED_XML)
    tree = factory.create_tree("Main")
    engine = sorted((node.uid, node.full_path, node.registration_id) for node in tree.nodes())

    outline = build_outline(NESTED_XML)
    ours = sorted(
        (node.uid, node.path, "SubTree" if node.is_subtree else node.type_id) for node in outline.nodes()
    )

    assert outline.exact_uids
    assert ours == engine


def test_outline_loads_subtrees_from_other_documents_and_reports_missing_ones() -> None:
    main = (
        '<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence><SubTree ID="A"/><SubTree ID="B"/>'
        "<AlwaysSuccess/></Sequence></BehaviorTree></root>"
    )
    other = '<root BTCPP_format="4"><BehaviorTree ID="A"><AlwaysSuccess name="in_a"/></BehaviorTree></root>'
    asked: list[str] = []

    def load(subtree_id: str) -> str | None:
        asked.append(subtree_id)
        return other if subtree_id == "A" else None

    outline = build_outline(main, "M", load_subtree=load)

    assert asked == ["A", "B"]
    assert [n.path for n in outline.nodes()] == [
        "Sequence::1",
        "A::2",
        "A::2/in_a",
        "B::4",
        "AlwaysSuccess::5",
    ]
    assert not outline.exact_uids and outline.missing_subtrees == ["B"]
    # With inexact numbering, a status change is matched by path only.
    assert outline.find(99, "A::2/in_a") is not None
    assert outline.find(3, "") is None


def test_outline_of_an_unknown_tree_names_the_known_ones() -> None:
    with pytest.raises(ObjectiveError, match="'Main'"):
        build_outline(NESTED_XML, "Mian")


def _entry(key: str, value: str, scope: str = "", type_name: str = "int") -> BlackboardEntry:
    return BlackboardEntry(scope, key, type_name, value)


def test_blackboard_model_reports_only_what_changed_and_keeps_history() -> None:
    model = BlackboardModel()
    first = model.apply("Obj", 1.0, [_entry("a", "1"), _entry("b", "2"), _entry("c", "3", scope="Sub::2")])
    assert [e.key for e in first.added] == ["a", "b", "c"] and not first.changed and not first.removed

    second = model.apply("Obj", 2.0, [_entry("a", "1"), _entry("b", "5"), _entry("d", "4")])
    assert [e.key for e in second.changed] == ["b"]
    assert [e.key for e in second.added] == ["d"]
    assert second.removed == [("Sub::2", "c")]
    assert list(model.history[("", "b")]) == [(1.0, "2"), (2.0, "5")]
    assert ("Sub::2", "c") not in model.history

    assert not model.apply("Obj", 3.0, [_entry("a", "1"), _entry("b", "5"), _entry("d", "4")])
    assert [e.key for e in model.matching("D")] == ["d"]


def test_merged_diffs_equal_the_diff_between_first_and_last_snapshot() -> None:
    snapshots = [
        [_entry("a", "1"), _entry("b", "1")],
        [_entry("a", "2"), _entry("c", "1")],
        [_entry("b", "9"), _entry("c", "1")],
        [_entry("b", "9"), _entry("c", "2"), _entry("a", "7")],
    ]
    model = BlackboardModel()
    model.apply("O", 0, snapshots[0])
    merged = BlackboardDiff()
    for snapshot in snapshots[1:]:
        merged = merged.merge(model.apply("O", 0, snapshot))

    # Applying the merged diff to the first snapshot gives the last one.
    table = {row_key(e): e.value for e in snapshots[0]}
    for key in merged.removed:
        del table[key]
    for entry in [*merged.added, *merged.changed]:
        table[row_key(entry)] = entry.value
    assert table == {row_key(e): e.value for e in snapshots[-1]}


def test_config_rows_name_the_package_that_set_each_value() -> None:
    resolved = resolve_config("example_config", Workspace.bundled_only(), check_files=False)
    rows = {row.key: row for row in config_rows(resolved)}

    assert rows["based_on_package"].package == "example_config"
    assert rows["objectives.objective_library_paths.example_objectives"].package == "example_config"
    inherited = [row for row in rows.values() if row.key.startswith("hardware.")]
    assert inherited and all(row.package == "lab_sim" for row in inherited)
    assert rows["objectives.objective_library_paths.example_objectives"].value == "example_config: objectives"


def test_package_files_are_relative_and_cut_at_the_limit(tmp_path) -> None:  # type: ignore[no-untyped-def]
    (tmp_path / "config").mkdir()
    (tmp_path / "config" / "config.yaml").write_text("a: 1\n")
    (tmp_path / ".git").mkdir()
    (tmp_path / ".git" / "HEAD").write_text("x")
    (tmp_path / "z.txt").write_text("")
    assert package_files(tmp_path) == (["z.txt", "config/config.yaml"], False)
    assert package_files(tmp_path, limit=1) == (["z.txt"], True)


def test_status_measures_elapsed_on_the_runtime_clock_and_forgets_a_lost_runtime() -> None:
    status = RuntimeStatus()
    status.apply_connection(ConnectionChanged(ConnectionState.CONNECTED, "tcp/127.0.0.1:7447"))
    assert not status.apply_heartbeat(Heartbeat(10.0, "", "Idle"))
    assert status.apply_heartbeat(Heartbeat(11.0, "Pick", "Running"))
    assert not status.apply_heartbeat(Heartbeat(13.5, "Pick", "Running"))
    assert status.elapsed == pytest.approx(2.5)
    status.apply_heartbeat(Heartbeat(14.0, "Pick", "Success"))
    status.apply_heartbeat(Heartbeat(20.0, "Pick", "Success"))
    assert status.elapsed == pytest.approx(3.0)
    assert status.apply_heartbeat(Heartbeat(21.0, "Place", "Running"))  # a new run
    status.apply_clock(ClockSample(4.0, 0.98))
    status.apply_connection(ConnectionChanged(ConnectionState.DISCONNECTED, "tcp/127.0.0.1:7447", "gone"))
    assert status.status == "Unknown" and status.sim_time is None


def test_reload_outcomes_are_recognised_in_the_runtime_log() -> None:
    from kinema.errors import SourceLocation
    from kinema.plugins.events import ReloadEvent, ReloadKind
    from kinema.tui.sdk_connection import reload_notice_from_log

    failed = ReloadEvent(
        ReloadKind.RELOAD_FAILED,
        "my_behaviors",
        "my_behaviors not reloaded, keeping the last good version: invalid syntax",
        SourceLocation("/ws/src/my_behaviors/my_behaviors/b.py", 7),
    )
    notice = reload_notice_from_log(str(failed), 1)
    assert notice is not None and not notice.ok
    assert notice.location == "/ws/src/my_behaviors/my_behaviors/b.py:7"
    assert notice.message.startswith("my_behaviors not reloaded")

    good = ReloadEvent(ReloadKind.BEHAVIORS_RELOADED, "x", "Reloaded my_behaviors: MyBehavior, Other")
    notice = reload_notice_from_log(str(good), 3)
    assert notice is not None and notice.ok and notice.behaviors == ("MyBehavior", "Other")

    changed = reload_notice_from_log("Objectives changed: pick.xml", 3)
    assert changed is not None and changed.kind == "objectives_changed"
    assert reload_notice_from_log("[MoveToWaypoint] planning took 2 s", 3) is None


def test_a_run_that_resumes_after_late_heartbeats_keeps_its_start() -> None:
    status = RuntimeStatus()
    endpoint = "tcp/127.0.0.1:7447"
    status.apply_connection(ConnectionChanged(ConnectionState.CONNECTED, endpoint))
    assert status.apply_heartbeat(Heartbeat(100.0, "Pick", "Running"))
    status.apply_connection(ConnectionChanged(ConnectionState.DISCONNECTED, endpoint, "late"))
    status.apply_connection(ConnectionChanged(ConnectionState.CONNECTED, endpoint))
    assert not status.apply_heartbeat(Heartbeat(105.0, "Pick", "Running"))  # not a new run
    assert status.elapsed == pytest.approx(5.0)
    assert status.apply_heartbeat(Heartbeat(106.0, "Place", "Running"))  # this one is


def test_the_behavior_catalog_lists_plugins_and_survives_a_config_that_is_not_here() -> None:
    from kinema.tui.connection import LogEntry
    from kinema.tui.sdk_connection import SdkConnection

    here = SdkConnection("tcp/127.0.0.1:9", config="lab_sim")
    catalog = {b.id: b for b in here.list_behaviors()}
    assert catalog["Sequence"].source == "built-in node"
    plugin_rows = [b for b in catalog.values() if b.plugin != "kinema.bt"]
    assert plugin_rows and all(b.location and b.source for b in plugin_rows)

    events: list[object] = []
    elsewhere = SdkConnection("tcp/127.0.0.1:9", config="config_of_another_machine")
    elsewhere._listener = events.append
    assert "Sequence" in {b.id for b in elsewhere.list_behaviors()}
    assert any(isinstance(e, LogEntry) and "config_of_another_machine" in e.message for e in events)


def test_the_status_line_shows_the_watchdog_warning_until_it_clears() -> None:
    from kinema.tui.widgets.status_bar import render_status

    status = RuntimeStatus()
    status.apply_connection(ConnectionChanged(ConnectionState.CONNECTED, "tcp/127.0.0.1:7447"))
    stuck = "behavior 'Block' (main/block) has been in tick for 3.4 s"
    status.apply_heartbeat(Heartbeat(1.0, "Pick", "Running", (stuck, "another")))
    line = render_status(status).plain
    assert "⚠ behavior 'Block' (main/block) has been in tick for 3 s (+1 more)" in line, line
    status.apply_heartbeat(Heartbeat(2.0, "Pick", "Cancelled"))
    assert "⚠" not in render_status(status).plain


def test_the_status_line_says_how_to_get_a_runtime_in_80_columns() -> None:
    # It showed "○ disconnected tcp/127.0.0.1:17901 — no Kinema router answers at" and the advice was cut.
    from kinema.tui.widgets.status_bar import render_status

    status = RuntimeStatus()
    endpoint = "tcp/127.0.0.1:17901"
    detail = f"no Kinema router answers at {endpoint} (start one with `kinema run`, or point --connect ...)"
    status.apply_connection(ConnectionChanged(ConnectionState.DISCONNECTED, endpoint, detail))
    line = render_status(status).plain
    assert line == f"○ disconnected {endpoint} — none answers: `kinema run` starts one"
    assert len(line) <= 78  # the bar's padding leaves 78 columns


def test_closing_while_the_runtime_is_unreachable_does_not_wait_for_the_attempt() -> None:
    """Quitting `kinema ui` that is still trying to reach a runtime: joining a router that does not answer
    takes zenoh about 2 s, and the app used to wait for the attempt (up to 5 s) before it closed."""
    import time

    from kinema.transport import free_endpoint
    from kinema.tui.sdk_connection import SdkConnection

    connection = SdkConnection(free_endpoint())  # a free port: nothing answers there
    events: list[object] = []
    connection.open(events.append)
    attempt = connection._thread
    assert attempt is not None
    time.sleep(0.3)  # the attempt is under way
    closed = time.monotonic()
    connection.close()
    took = time.monotonic() - closed
    events_at_close = len(events)
    attempt.join(30.0)
    assert not attempt.is_alive(), "the connection thread never ended after close()"
    # A generous bound: the attempt alone takes ~2 s, which close() used to wait out.
    assert took < 1.5, f"close() took {took:.1f} s"
    assert len(events) == events_at_close, "the app got events after it closed the connection"
    assert connection._client is None


def _a_run_that_succeeded(endpoint: str) -> RuntimeStatus:
    """'Pick Cube' ran 4.2 s and succeeded; the server says Idle two seconds later."""
    status = RuntimeStatus()
    status.apply_connection(ConnectionChanged(ConnectionState.CONNECTED, endpoint))
    status.apply_heartbeat(Heartbeat(10.0, "Pick Cube", "Running"))
    status.apply_heartbeat(Heartbeat(14.2, "Pick Cube", "Success"))
    status.apply_heartbeat(Heartbeat(16.2, "Pick Cube", "Idle"))
    return status


def test_the_status_line_keeps_how_the_last_run_ended_once_the_server_is_idle() -> None:
    # It read "Pick Cube Idle 4.2 s" after a success and after a cancel alike.
    from kinema.tui.widgets.status_bar import render_status

    status = _a_run_that_succeeded("tcp/127.0.0.1:7447")
    assert "│  Pick Cube Success 4.2 s · idle" in render_status(status).plain
    status.apply_heartbeat(Heartbeat(20.0, "Pick Cube", "Running"))
    assert "Pick Cube Running" in render_status(status).plain and "idle" not in render_status(status).plain
    status.apply_heartbeat(Heartbeat(21.5, "Pick Cube", "Cancelled"))
    status.apply_heartbeat(Heartbeat(23.5, "Pick Cube", "Idle"))
    assert "Pick Cube Cancelled 1.5 s · idle" in render_status(status).plain


def test_the_status_line_drops_the_endpoint_before_the_clock_in_80_columns() -> None:
    # It ended "sim 19.57 s  RTF" at 80 columns: the factor itself was cut.
    from kinema.tui.connection import ClockSample
    from kinema.tui.widgets.status_bar import render_status

    status = _a_run_that_succeeded("tcp/127.0.0.1:27461")
    status.apply_clock(ClockSample(19.57, 1.0))
    narrow = render_status(status, 78).plain
    assert narrow.endswith("sim 19.57 s  RTF 1.00x") and len(narrow) <= 78, narrow
    assert "tcp/127.0.0.1:27461" not in narrow
    assert "tcp/127.0.0.1:27461" in render_status(status, 200).plain
    # A long objective name: the factor goes too, whole, rather than cut at the edge.
    status.apply_heartbeat(Heartbeat(20.0, "3 Waypoints Pick and Place", "Running"))
    status.apply_heartbeat(Heartbeat(25.8, "3 Waypoints Pick and Place", "Running"))
    running = render_status(status, 78).plain
    assert running.endswith("3 Waypoints Pick and Place Running 5.8 s  │  sim 19.57 s"), running
    assert len(running) <= 78
