"""The agent's tree source: objective folders, files that do not load, and rebuilding after changes."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from kinema.bt import WallClock
from kinema.runtime.objective_server import ObjectiveRequest, ObjectiveServer
from kinema.runtime.objective_source import LibraryTreeSource, library_from_folders

GOOD = '<root BTCPP_format="4"><BehaviorTree ID="Good"><AlwaysSuccess/></BehaviorTree></root>'
BROKEN = '<root BTCPP_format="4"><BehaviorTree ID="Broken"><NoSuchBehavior/></BehaviorTree></root>'


def _source(folder: Path) -> LibraryTreeSource:
    load = lambda: library_from_folders([folder])  # noqa: E731 - the source calls it again after changes
    return LibraryTreeSource(load, host=None, context=None, clock=WallClock())


def test_only_objectives_whose_file_loads_are_runnable_and_the_others_say_why(tmp_path: Path) -> None:
    (tmp_path / "good.xml").write_text(GOOD)
    (tmp_path / "broken.xml").write_text(BROKEN)
    source = _source(tmp_path)
    assert source.objective_names() == ["Good"]
    assert [info.id for info in source.objectives()] == ["Broken", "Good"]
    with ObjectiveServer(source) as server:
        assert server.submit(ObjectiveRequest("Good")).wait(5).succeeded  # type: ignore[union-attr]
        result = server.submit(ObjectiveRequest("Broken")).wait(5)
    assert result is not None and result.failed
    assert "objective 'Broken' cannot run" in result.error_message
    assert "broken.xml" in result.error_message and "NoSuchBehavior" in result.error_message


def test_a_subtree_that_did_not_load_is_reported_with_its_own_reason(tmp_path: Path) -> None:
    # It said "Can't find a tree with name: Broken", as if the subtree did not exist.
    (tmp_path / "caller.xml").write_text(
        '<root BTCPP_format="4">\n'
        '  <BehaviorTree ID="Caller">\n'
        '    <SubTree ID="Broken"/>\n'
        "  </BehaviorTree>\n"
        "</root>\n"
    )
    (tmp_path / "broken.xml").write_text(BROKEN)
    source = _source(tmp_path)
    assert source.objective_names() == ["Caller"]
    with ObjectiveServer(source) as server:
        result = server.submit(ObjectiveRequest("Caller")).wait(5)
        xml = (tmp_path / "caller.xml").read_text()
        from_xml = server.submit(ObjectiveRequest(objective_xml=xml)).wait(5)
    for outcome in (result, from_xml):
        assert outcome is not None and outcome.failed
        message = outcome.error_message
        assert "objective 'Caller' cannot run: its SubTree 'Broken' did not load:" in message, message
        assert "broken.xml" in message and "NoSuchBehavior" in message
        assert "Can't find a tree" not in message
    assert f"{tmp_path / 'caller.xml'}:3:" in result.error_message


def test_changed_objective_files_are_picked_up_after_invalidation(tmp_path: Path) -> None:
    (tmp_path / "good.xml").write_text(GOOD)
    source = _source(tmp_path)
    first = source.factory()
    assert source.factory() is first  # nothing changed: the factory is kept
    (tmp_path / "later.xml").write_text(GOOD.replace("Good", "Later"))
    source.invalidate_objectives()
    assert source.factory() is not first
    assert source.objective_names() == ["Good", "Later"]


def test_an_objective_saved_before_hot_reload_reports_it_runs_by_name(tmp_path: Path) -> None:
    # The tutorial's step: save a new objective file, run it by name at once. Hot reload waits for the
    # folder to be quiet before it reports the file; asking for a name the library does not know reads
    # the files again first. A name that is in no file is still unknown.
    (tmp_path / "good.xml").write_text(GOOD)
    source = _source(tmp_path)
    assert source.objective_names() == ["Good"]
    (tmp_path / "later.xml").write_text(GOOD.replace("Good", "Later"))
    with ObjectiveServer(source) as server:
        assert server.submit(ObjectiveRequest("Later")).wait(5).succeeded  # type: ignore[union-attr]
        result = server.submit(ObjectiveRequest("Nowhere")).wait(5)
    assert result is not None and result.failed
    assert "unknown objective 'Nowhere'" in result.error_message


def test_a_client_that_lists_objectives_as_soon_as_it_reads_the_reload_notice_gets_the_new_list(
    tmp_path: Path,
) -> None:
    # The TUI asks for the list when the notice arrives; the notice went out before the library was
    # marked stale, so a quick enough ask got the old list, and no second notice came while the files
    # stayed as they were (the TUI showed one objective for good; a loaded CI machine hit it).
    from kinema.plugins.events import ReloadEvent, ReloadKind
    from kinema.runtime.agent import Agent

    (tmp_path / "good.xml").write_text(GOOD)
    source = _source(tmp_path)
    source.factory()  # as the agent loads it at start
    assert [info.id for info in source.objectives()] == ["Good"]
    (tmp_path / "later.xml").write_text(GOOD.replace("Good", "Later"))
    seen_with_notice: list[list[str]] = []

    def publish_log(level: int, text: str) -> None:
        seen_with_notice.append([info.id for info in source.objectives()])

    agent = _agent_over(source, publish_log)
    event = ReloadEvent(ReloadKind.OBJECTIVES_CHANGED, str(tmp_path), "objectives changed: later.xml")
    Agent.on_reload_event(agent, event)  # type: ignore[arg-type]
    assert seen_with_notice == [["Good", "Later"]]


def _agent_over(source: LibraryTreeSource, publish_log: Callable[[int, str], None]) -> Any:
    """Enough of an Agent for its reload handling: the tree source and a log stream."""
    from types import SimpleNamespace

    from kinema.runtime.agent import Agent

    agent = SimpleNamespace(source=source, _streams=SimpleNamespace(publish_log=publish_log))
    agent._check_changed_objectives = lambda paths: Agent._check_changed_objectives(agent, paths)  # type: ignore[arg-type]
    return agent


def test_an_objective_saved_with_a_wrong_port_is_reported_at_the_save_not_at_its_run(tmp_path: Path) -> None:
    # A new user changed mass_kg= to mass_gk= while the runtime ran: it said only "Objectives changed".
    from kinema.plugins.events import ReloadEvent, ReloadKind
    from kinema.runtime.agent import Agent

    good = tmp_path / "good.xml"
    good.write_text(GOOD)
    source = _source(tmp_path)
    source.factory()
    good.write_text(
        GOOD.replace("<AlwaysSuccess/>", '<Sequence>\n<SetBlackboard value="1" ky="x"/></Sequence>')
    )
    said: list[tuple[int, str]] = []
    agent = _agent_over(source, lambda level, text: said.append((level, text)))
    event = ReloadEvent(
        ReloadKind.OBJECTIVES_CHANGED, str(tmp_path), "Objectives changed: good.xml", paths=(str(good),)
    )
    Agent.on_reload_event(agent, event)  # type: ignore[arg-type]
    warnings = [text for level, text in said if level == 2]
    assert len(warnings) == 1, said
    assert warnings[0].startswith(f"{good}:2: ") and "[ky]" in warnings[0], warnings


def test_a_file_saved_broken_keeps_its_last_good_version_through_a_rebuild(tmp_path: Path) -> None:
    # Hot reload does not report a broken save, so the objective ran its last good version; then a
    # behavior package reloaded, the source rebuilt from the files, and the objective was gone.
    (tmp_path / "good.xml").write_text(GOOD)
    (tmp_path / "other.xml").write_text(GOOD.replace("Good", "Other"))
    source = _source(tmp_path)
    assert source.objective_names() == ["Good", "Other"]
    with ObjectiveServer(source) as server:
        for broken in (
            GOOD.replace("</BehaviorTree>", "</BehaviourTree>"),  # not XML: the library cannot read it
            GOOD.replace("AlwaysSuccess", "AlwaysSucess"),  # reads, but does not load
        ):
            (tmp_path / "good.xml").write_text(broken)
            source.invalidate_objectives()  # what a behavior reload or another saved file leads to
            assert source.objective_names() == ["Good", "Other"]
            assert [info.id for info in source.objectives()] == ["Good", "Other"]
            assert server.submit(ObjectiveRequest("Good")).wait(5).succeeded  # type: ignore[union-attr]
        # Fixed, the file's new version runs: here it fails, so it is the new one.
        (tmp_path / "good.xml").write_text(GOOD.replace("AlwaysSuccess", "AlwaysFailure"))
        source.invalidate_objectives()
        assert server.submit(ObjectiveRequest("Good")).wait(5).failed  # type: ignore[union-attr]
        # Deleted, it is gone.
        (tmp_path / "good.xml").unlink()
        source.invalidate_objectives()
        assert source.objective_names() == ["Other"]
