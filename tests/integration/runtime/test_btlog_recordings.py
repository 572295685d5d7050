""".btlog recordings: the same tree recorded by BT.CPP's FileLogger2 and by Kinema gives the same file.

Byte for byte except where the content cannot agree: the first timestamp and the transitions' times
(two runs), and the XML's attribute order. Then the runtime's recorder: one file per run, listed by
`kinema logs --recordings`, zipped by `kinema export-logs`, bounded in size.
"""

from __future__ import annotations

import gc
import struct
import time
import zipfile
from pathlib import Path

import pytest
from groot2_oracle import FAILING_XML, RUNNING_XML, assert_same_tree_xml, btcpp, btcpp_tree, kinema_tree

from kinema.bt.btlog import MAGIC, BtlogError, FileLogger2, parse_btlog, read_btlog
from kinema.bt.status import NodeStatus


def _record_btcpp(xml: str, main: str, path: Path, ticks: int | None) -> None:
    tree = btcpp_tree(xml, main)
    logger = btcpp().FileLogger(tree, str(path))
    if ticks is None:
        tree.tick_while_running(1)
    else:
        for _ in range(ticks):
            tree.tick_once()
    # BT.CPP's writer thread drains its queue every 10 ms, and its destructor drops what is still
    # queued: wait until the file stops growing before letting go of the logger (its flush() races
    # with that thread, so it is not called).
    last, steady_since, deadline = -1, time.monotonic(), time.monotonic() + 10
    while time.monotonic() < deadline:
        size = path.stat().st_size
        if size != last:
            last, steady_since = size, time.monotonic()
        elif time.monotonic() - steady_since > 0.2:
            break
        time.sleep(0.01)
    del logger
    gc.collect()


def _record_kinema(xml: str, main: str, path: Path, ticks: int | None) -> None:
    tree = kinema_tree(xml, main)
    with FileLogger2(tree, path):
        if ticks is None:
            tree.tick_while_running(0.001)
        else:
            for _ in range(ticks):
                tree.tick_once()


def _layout(data: bytes) -> tuple[bytes, int, int]:
    """(magic + protocol, XML length field, length of everything after the XML)."""
    (xml_size,) = struct.unpack_from("<i", data, 19)
    return data[:19], xml_size, len(data) - 23 - xml_size


@pytest.mark.parametrize(("xml", "main", "ticks"), [(FAILING_XML, "Fails", None), (RUNNING_XML, "Main", 3)])
def test_btlog_file_matches_btcpp_file_logger2(
    tmp_path: Path, xml: str, main: str, ticks: int | None
) -> None:
    btcpp()
    theirs_path, ours_path = tmp_path / "btcpp.btlog", tmp_path / "kinema.btlog"
    _record_btcpp(xml, main, theirs_path, ticks)
    _record_kinema(xml, main, ours_path, ticks)
    theirs_bytes, ours_bytes = theirs_path.read_bytes(), ours_path.read_bytes()

    assert ours_bytes[:19] == theirs_bytes[:19] == MAGIC + b"\x01"
    theirs, ours = read_btlog(theirs_path), read_btlog(ours_path)
    assert_same_tree_xml(ours.tree_xml, theirs.tree_xml)
    # Same XML up to attribute order and C++ port type names; the length field says how long it is.
    assert _layout(ours_bytes)[1] == len(ours.tree_xml.encode())
    # The first timestamp is microseconds since the epoch in both (the two recordings are seconds apart).
    assert abs(ours.start_epoch_us - theirs.start_epoch_us) < 60e6
    assert [(t.uid, t.status) for t in ours.transitions] == [(t.uid, t.status) for t in theirs.transitions]
    assert ours.trailing_bytes == theirs.trailing_bytes == 0
    assert _layout(ours_bytes)[2] == _layout(theirs_bytes)[2] == 8 + 9 * len(theirs.transitions)
    offsets = [t.offset_us for t in ours.transitions]
    assert offsets == sorted(offsets) and offsets[-1] < 60e6
    # IDLE transitions are recorded too (FileLogger2 enables them): replay shows nodes being reset.
    assert any(t.status is NodeStatus.IDLE for t in ours.transitions)


def test_reading_a_recording_cut_short_and_bad_files(tmp_path: Path) -> None:
    path = tmp_path / "run.btlog"
    _record_kinema(FAILING_XML, "Fails", path, None)
    full = read_btlog(path)
    cut = parse_btlog(path.read_bytes()[:-4], path)
    assert cut.transitions == full.transitions[:-1] and cut.trailing_bytes == 5
    assert full.statuses_at(0) == {}
    assert full.statuses_at(len(full.transitions))[1] is NodeStatus.IDLE

    other = tmp_path / "other.btlog"
    other.write_bytes(b"BTCPP3-FileLogger stuff")
    with pytest.raises(BtlogError, match=r"other\.btlog.*not a BT\.CPP FileLogger2 recording"):
        read_btlog(other)
    with pytest.raises(BtlogError, match=r"must end in \.btlog, got 'run\.log'"):
        FileLogger2(kinema_tree(FAILING_XML, "Fails"), tmp_path / "run.log")


def test_the_size_cap_stops_a_recording_growing(tmp_path: Path) -> None:
    from kinema.bt.btlog import header_bytes
    from kinema.bt.model_xml import write_tree_to_xml

    tree = kinema_tree(RUNNING_XML, "Main")
    path = tmp_path / "capped.btlog"
    cap = len(header_bytes(write_tree_to_xml(tree), 0)) + 9 * 20 + 4
    with FileLogger2(tree, path, max_bytes=cap):
        for _ in range(50):
            tree.tick_once()
    recording = read_btlog(path)
    assert len(recording.transitions) == 20
    assert path.stat().st_size <= cap


def _server_with_recorder(tmp_path: Path, **limits: int):
    from kinema.bt import BehaviorTreeFactory
    from kinema.runtime.objective_server import FactoryTreeSource, ObjectiveServer
    from kinema.runtime.recordings import RunRecorder

    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(FAILING_XML)
    factory.register_behavior_tree_from_text(RUNNING_XML)
    recorder = RunRecorder(tmp_path / "recordings", **limits)
    return ObjectiveServer(FactoryTreeSource(factory), listeners=[recorder], tick_rate_hz=500), recorder


def test_the_objective_server_records_each_run_in_its_own_file(tmp_path: Path) -> None:
    from kinema.runtime.objective_server import ObjectiveRequest
    from kinema.runtime.recordings import list_recordings

    server, recorder = _server_with_recorder(tmp_path)
    with server:
        assert server.submit(ObjectiveRequest(objective_name="Fails")).wait(30).failed
        run = server.submit(ObjectiveRequest(objective_name="Main"))
        deadline = time.monotonic() + 30
        while (
            recorder.current is None or "Main" not in recorder.current.name
        ) and time.monotonic() < deadline:
            time.sleep(0.01)
        run.cancel()
        assert run.wait(30).cancelled
    files = list_recordings(tmp_path / "recordings")
    assert [f.objective_name for f in files] == ["Fails", "Main"]
    failed = read_btlog(files[0].path)
    reference = tmp_path / "reference.btlog"
    _record_kinema(FAILING_XML, "Fails", reference, None)
    assert [(t.uid, t.status) for t in failed.transitions] == [
        (t.uid, t.status) for t in read_btlog(reference).transitions
    ]
    assert_same_tree_xml(failed.tree_xml, read_btlog(reference).tree_xml)
    cancelled = read_btlog(files[1].path)
    # The cancelled run's halt is recorded: its last transitions put the running nodes back to IDLE.
    assert cancelled.transitions[-1].status is NodeStatus.IDLE
    assert NodeStatus.RUNNING in {t.status for t in cancelled.transitions}


def test_rotation_keeps_the_newest_recordings_within_the_limits(tmp_path: Path) -> None:
    from kinema.runtime.objective_server import ObjectiveRequest
    from kinema.runtime.recordings import list_recordings

    server, _ = _server_with_recorder(tmp_path, keep=3, max_file_bytes=40_000, max_total_bytes=1_000_000)
    with server:
        for _ in range(5):
            assert server.submit(ObjectiveRequest(objective_name="Fails")).wait(30).failed
    files = list_recordings(tmp_path / "recordings")
    assert len(files) == 3, files
    assert all(f.objective_name == "Fails" for f in files)

    tight, _ = _server_with_recorder(tmp_path, keep=100, max_file_bytes=40_000, max_total_bytes=80_000)
    with tight:
        for _ in range(3):
            assert tight.submit(ObjectiveRequest(objective_name="Fails")).wait(30).failed
    assert sum(f.size for f in list_recordings(tmp_path / "recordings")) <= 80_000


def test_kinema_logs_lists_recordings_and_export_logs_zips_them(tmp_path: Path, monkeypatch) -> None:
    from click.testing import CliRunner

    from kinema.cli.logs import export_logs, logs
    from kinema.runtime.recordings import FOLDER_NAME

    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    from kinema.runtime.run_folder import RunFolder

    folder = RunFolder.create("lab_sim")
    folder.log_file("agent").write_text("2026-11-24 05:00:00.000 INFO    [agent] hello\n")
    recordings = folder.path / FOLDER_NAME
    recordings.mkdir()
    _record_kinema(FAILING_XML, "Fails", recordings / "20261124-050000-000001-Fails.btlog", None)

    result = CliRunner().invoke(logs, ["--recordings"])
    assert result.exit_code == 0, result.output
    assert "20261124-050000-000001-Fails.btlog" in result.output
    assert "Fails" in result.output and "transitions" in result.output
    assert "hello" not in result.output

    target = tmp_path / "out.zip"
    result = CliRunner().invoke(export_logs, ["-o", str(target)])
    assert result.exit_code == 0, result.output
    names = zipfile.ZipFile(target).namelist()
    assert f"{folder.name}/{FOLDER_NAME}/20261124-050000-000001-Fails.btlog" in names
    assert f"{folder.name}/agent.log" in names


def test_a_run_ended_by_an_exception_is_recorded_and_served_as_halted(tmp_path: Path) -> None:
    """The server halts the tree when a behavior raises; the halt must reach the recording and Groot2."""
    from groot2_oracle import Groot2Client, free_port_pair

    from kinema.bt import BehaviorTreeFactory, NodeStatus, SyncActionNode
    from kinema.runtime.groot2 import Groot2Server
    from kinema.runtime.objective_server import FactoryTreeSource, ObjectiveRequest, ObjectiveServer
    from kinema.runtime.recordings import RunRecorder, list_recordings

    class RaiseOnSecondTick(SyncActionNode):
        ticks = 0

        def tick(self) -> NodeStatus:
            type(self).ticks += 1
            if type(self).ticks >= 2:
                raise RuntimeError("the gripper driver went away")
            return NodeStatus.SUCCESS

    factory = BehaviorTreeFactory()
    factory.register_node_type(RaiseOnSecondTick)
    factory.register_behavior_tree_from_text(
        """<root BTCPP_format="4"><BehaviorTree ID="Breaks">
             <ReactiveSequence>
               <RaiseOnSecondTick name="boom"/>
               <Sleep name="wait" msec="100000"/>
             </ReactiveSequence>
           </BehaviorTree></root>"""
    )
    port = free_port_pair()
    recorder = RunRecorder(tmp_path / "recordings")
    with Groot2Server(port) as groot2:
        client = Groot2Client(port)
        try:
            listeners = [recorder, groot2]
            with ObjectiveServer(FactoryTreeSource(factory), listeners=listeners, tick_rate_hz=200) as server:
                result = server.submit(ObjectiveRequest(objective_name="Breaks")).wait(30)
            assert result is not None and result.failed and "the gripper driver went away" in str(result)
            status = client.request("S")[1]
        finally:
            client.close()
    (file,) = list_recordings(tmp_path / "recordings")
    recording = read_btlog(file.path)
    final = recording.statuses_at(len(recording.transitions))
    assert final[3] is NodeStatus.IDLE, "the Sleep that was RUNNING ends halted (IDLE), not RUNNING"
    assert (3, NodeStatus.RUNNING) in [(t.uid, t.status) for t in recording.transitions]
    assert struct.pack("<HB", 3, 11) in status, f"Groot2 sees the Sleep IDLE after RUNNING: {status.hex()}"
