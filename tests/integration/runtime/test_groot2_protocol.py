"""Groot2 attaches to Kinema as it does to BT.CPP: the same tree in both, the same requests, the same replies.

BT.CPP's own ``Groot2Publisher`` (behaviortreepy) is the oracle: each test builds one tree in BT.CPP
and in Kinema, serves both, sends both what Groot2 sends, and compares the replies.
"""

from __future__ import annotations

import struct
import threading
import time
from pathlib import Path

import msgpack
import pytest
from groot2_oracle import (
    FAILING_XML,
    RUNNING_XML,
    Groot2Client,
    assert_same_tree_xml,
    btcpp,
    btcpp_tree,
    free_port_pair,
    kinema_tree,
)

pytest.importorskip("zmq", reason="pyzmq speaks the Groot2 protocol")


def _served(xml: str, main: str):
    """(BT.CPP tree, its publisher, client), (Kinema tree, its publisher, client)."""
    from kinema.runtime.groot2 import Groot2Publisher

    theirs = btcpp_tree(xml, main)
    their_port = free_port_pair()
    their_publisher = btcpp().Groot2Publisher(theirs, their_port)
    ours = kinema_tree(xml, main)
    our_port = free_port_pair()
    our_publisher = Groot2Publisher(ours, our_port)
    return (theirs, their_publisher, Groot2Client(their_port)), (ours, our_publisher, Groot2Client(our_port))


def _scopes(client: Groot2Client, names: str) -> object:
    return msgpack.unpackb(client.request("B", names.encode())[1])


@pytest.fixture
def running_pair():
    (theirs, their_pub, their_client), (ours, our_pub, our_client) = _served(RUNNING_XML, "Main")
    yield theirs, their_client, ours, our_client
    their_client.close()
    our_client.close()
    our_pub.close()
    del their_pub


def test_tree_status_and_blackboard_replies_match_btcpp_while_running(running_pair) -> None:
    theirs, their_client, ours, our_client = running_pair
    assert str(theirs.tick_once()).endswith("RUNNING")
    assert ours.tick_once().name == "RUNNING"

    their_tree, our_tree = their_client.request("T"), our_client.request("T")
    assert len(our_tree) == len(their_tree) == 2
    assert len(our_tree[0]) == len(their_tree[0]) == 22, "6-byte request header + 16-byte tree id"
    assert_same_tree_xml(our_tree[1].decode(), their_tree[1].decode())

    their_status, our_status = their_client.request("S")[1], our_client.request("S")[1]
    assert our_status == their_status, f"kinema {our_status.hex()} vs BT.CPP {their_status.hex()}"
    # RUNNING nodes are there, as Groot2 colours them.
    assert struct.pack("<HB", 1, 1) in our_status

    names = "Main;AddOne::4;NoSuchScope"
    theirs_bb, ours_bb = _scopes(their_client, names), _scopes(our_client, names)
    assert ours_bb == theirs_bb, f"kinema {ours_bb} vs BT.CPP {theirs_bb}"
    assert ours_bb["Main"]["sum"] == 2 and ours_bb["AddOne::4"]["note"] == "inner", ours_bb
    # No matching scope: both answer msgpack nil.
    assert our_client.request("B", b"Nope")[1] == their_client.request("B", b"Nope")[1] == b"\xc0"


def test_final_statuses_after_a_failed_run_match_btcpp() -> None:
    (theirs, their_pub, their_client), (ours, our_pub, our_client) = _served(FAILING_XML, "Fails")
    try:
        assert str(theirs.tick_while_running(1)).endswith("FAILURE")
        assert ours.tick_while_running(0.001).name == "FAILURE"
        their_status, our_status = their_client.request("S")[1], our_client.request("S")[1]
        # After the run every node is IDLE again, and the byte says what it was before (10 + status):
        # that is how Groot2 still shows the failed node in red.
        assert our_status == their_status, f"kinema {our_status.hex()} vs BT.CPP {their_status.hex()}"
        assert struct.pack("<HB", 1, 13) in our_status, "the root sequence shows it failed"
        assert _scopes(our_client, "Fails;Inner::3") == _scopes(their_client, "Fails;Inner::3")
        assert_same_tree_xml(our_client.request("T")[1].decode(), their_client.request("T")[1].decode())
    finally:
        their_client.close()
        our_client.close()
        our_pub.close()
        del their_pub


def test_recorded_transitions_match_btcpp(running_pair) -> None:
    theirs, their_client, ours, our_client = running_pair
    their_start = their_client.request("r", b"start")
    our_start = our_client.request("r", b"start")
    # Both answer "start" with the wall time in microseconds since the epoch.
    for reply in (their_start, our_start):
        assert abs(int(reply[1]) / 1e6 - time.time()) < 60, reply
    theirs.tick_once()
    theirs.tick_once()
    ours.tick_once()
    ours.tick_once()
    from kinema.runtime.groot2 import transitions_from_bytes

    their_transitions = transitions_from_bytes(their_client.request("t")[1])
    our_transitions = transitions_from_bytes(our_client.request("t")[1])
    assert [(uid, status) for _, uid, status in our_transitions] == [
        (uid, status) for _, uid, status in their_transitions
    ]
    assert len(our_transitions) > 10
    stamps = [stamp for stamp, _, _ in our_transitions]
    assert stamps == sorted(stamps)
    # Fetching clears them, in both.
    assert our_client.request("t")[1] == their_client.request("t")[1] == b""
    assert len(our_client.request("r", b"stop")) == len(their_client.request("r", b"stop")) == 1
    ours.tick_once()
    assert our_client.request("t")[1] == b"", "no transitions are kept once recording stopped"


def test_hook_requests_and_bad_headers(running_pair) -> None:
    _, their_client, _, our_client = running_pair
    assert our_client.request("D")[1:] == their_client.request("D")[1:] == [b"[]"]
    assert len(our_client.request("A")) == len(their_client.request("A")) == 1
    reply = our_client.request("I", b'{"uid": 1, "position": 0, "mode": 0, "once": false, "enabled": true}')
    assert reply[0] == b"error" and b"breakpoints are not supported" in reply[1]
    assert our_client.request("Z") == their_client.request("Z") == [b"error", b"Request not recognized"]


def test_the_objective_server_serves_each_new_objective_under_a_new_tree_id() -> None:
    from kinema.bt import BehaviorTreeFactory
    from kinema.runtime.groot2 import Groot2Server
    from kinema.runtime.objective_server import FactoryTreeSource, ObjectiveRequest, ObjectiveServer

    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(FAILING_XML)
    factory.register_behavior_tree_from_text(RUNNING_XML)
    port = free_port_pair()
    groot2 = Groot2Server(port)
    client = Groot2Client(port)
    try:
        assert client.request("T")[0] == b"error", "nothing to show before the first objective"
        with ObjectiveServer(FactoryTreeSource(factory), listeners=[groot2], tick_rate_hz=200) as server:
            result = server.submit(ObjectiveRequest(objective_name="Fails")).wait(30)
            assert result is not None and result.failed, result
            first_id = client.tree_id()
            first_xml = client.request("T")[1].decode()
            assert 'BehaviorTree ID="Fails"' in first_xml
            # The finished run stays visible: its failed root still reads "IDLE after FAILURE".
            assert struct.pack("<HB", 1, 13) in client.request("S")[1]

            theirs = btcpp_tree(RUNNING_XML, "Main")
            their_port = free_port_pair()
            their_pub = btcpp().Groot2Publisher(theirs, their_port)
            their_client = Groot2Client(their_port)
            try:
                theirs.tick_once()
                run = server.submit(ObjectiveRequest(objective_name="Main"))
                deadline = time.monotonic() + 30
                while client.tree_id() == first_id and time.monotonic() < deadline:
                    time.sleep(0.02)
                assert client.tree_id() != first_id, "a new objective gets a new tree id"
                assert_same_tree_xml(client.request("T")[1].decode(), their_client.request("T")[1].decode())
                expected = their_client.request("S")[1]
                while client.request("S")[1] != expected and time.monotonic() < deadline:
                    time.sleep(0.02)
                assert client.request("S")[1] == expected
                assert _scopes(client, "Main") == _scopes(their_client, "Main")
                run.cancel()
            finally:
                their_client.close()
                del their_pub
    finally:
        client.close()
        groot2.close()


def test_a_busy_port_is_a_clear_error() -> None:
    from kinema.errors import KinemaError
    from kinema.runtime.groot2 import Groot2Server

    port = free_port_pair()
    with Groot2Server(port):
        with pytest.raises(KinemaError, match=rf"cannot serve Groot2 on 127\.0\.0\.1:{port}.*--groot2-port"):
            Groot2Server(port)


def test_requests_from_another_thread_while_the_tree_ticks() -> None:
    from kinema.runtime.groot2 import Groot2Publisher

    tree = kinema_tree(RUNNING_XML, "Main")
    port = free_port_pair()
    stop = threading.Event()

    def tick() -> None:
        while not stop.is_set():
            tree.tick_once()

    with Groot2Publisher(tree, port):
        client = Groot2Client(port)
        ticker = threading.Thread(target=tick)
        ticker.start()
        try:
            for _ in range(200):
                assert len(client.request("S")[1]) == 3 * len(tree)
                assert "Main" in _scopes(client, "Main;AddOne::4")
        finally:
            stop.set()
            ticker.join()
            client.close()


def _this_folders_conftest(request: pytest.FixtureRequest):
    # Every test folder has a module called conftest: ask pytest for the one beside this file.
    wanted = Path(__file__).with_name("conftest.py")
    for plugin in request.config.pluginmanager.get_plugins():
        if Path(getattr(plugin, "__file__", "") or "/").resolve() == wanted.resolve():
            return plugin
    raise LookupError(f"{wanted} is not loaded")


def test_the_agent_process_serves_groot2_and_records_runs(tmp_path: Path, request) -> None:
    fixtures = _this_folders_conftest(request)
    start_agent, stop_agent = fixtures.start_agent, fixtures.stop_agent
    from kinema.bt.btlog import read_btlog
    from kinema.runtime.recordings import list_recordings
    from kinema.sdk import ObjectiveClient

    port = free_port_pair()
    recordings = tmp_path / "recordings"
    agent = start_agent(tmp_path, "--groot2-port", str(port), "--recordings", str(recordings))
    client = Groot2Client(port)
    try:
        with ObjectiveClient(agent.endpoint, timeout=10) as sdk:
            result = sdk.execute("Fails", wait=True)
        assert result.failed, result
        tree = client.request("T")[1].decode()
        assert 'BehaviorTree ID="Fails"' in tree and 'name="broken"' in tree
        broken_uid = int(tree.split('name="broken" _uid="')[1].split('"')[0])
        # The client has its result first; Groot2 and the recorder hear of the end right after.
        deadline = time.monotonic() + 10
        while struct.pack("<HB", broken_uid, 13) not in client.request("S")[1]:
            assert time.monotonic() < deadline, "the failed node never read IDLE-after-FAILURE"
            time.sleep(0.02)
        while not (files := list_recordings(recordings)):
            assert time.monotonic() < deadline, "the run was never recorded"
            time.sleep(0.02)
        assert [f.objective_name for f in files] == ["Fails"], files
        recording = read_btlog(files[0].path)
        assert (broken_uid, 3) in [(t.uid, int(t.status)) for t in recording.transitions]
    finally:
        client.close()
        stop_agent(agent)
    assert "Groot2 can attach at 127.0.0.1" in agent.log_file.read_text()
