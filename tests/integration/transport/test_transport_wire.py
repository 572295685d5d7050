"""The bytes on the wire, checked with a raw zenoh session against rmw_zenoh's format.

Expected values are assembled by hand from the rmw_zenoh design (keys, tokens, the 33-byte attachment,
CDR with its 4-byte header) and from the reference wire capture, not produced by Kinema's own encoders.
"""

from __future__ import annotations

import json
import queue
import struct
import time
from collections.abc import Callable, Iterator

import pytest
import zenoh

from kinema.transport import Node, Session

STRING_HASH = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
ADD_HASH = "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
FEEDBACK_HASH = "RIHS01_c1de71afd52e49a89c53d8262366884185bc0a02f78ce051c4e46b0a7fe59bb2"
STATUS_HASH = "RIHS01_6c1684b00f177d37438febe6e709fc4e2b0d4248dca4854946f9ed8b30cda83e"
DEFAULT_QOS = "::,10:,:,:,,"
LATCHED_QOS = ":1:,1:,:,:,,"


@pytest.fixture
def spy(router: Session, router_endpoint: str) -> Iterator[zenoh.Session]:
    """A plain zenoh session (no Kinema code) joined to the test router."""
    config = zenoh.Config.from_json5(
        json.dumps(
            {
                "mode": "peer",
                "connect": {"endpoints": [router_endpoint]},
                "listen": {"endpoints": ["tcp/127.0.0.1:0"]},
                "scouting": {"multicast": {"enabled": False}},
            }
        )
    )
    session = zenoh.open(config)
    yield session
    session.close()


def _tokens(spy: zenoh.Session, wanted: Callable[[set[str]], bool]) -> set[str]:
    deadline = time.monotonic() + 5
    while True:
        tokens = {
            str(reply.ok.key_expr) for reply in spy.liveliness().get("@ros2_lv/**", timeout=2) if reply.ok
        }
        if wanted(tokens) or time.monotonic() > deadline:
            return tokens
        time.sleep(0.02)


def test_published_sample_has_rmw_zenoh_key_cdr_and_attachment(
    connect: Callable[[], Session], spy: zenoh.Session
) -> None:
    samples: queue.Queue[zenoh.Sample] = queue.Queue()
    subscriber = spy.declare_subscriber("0/chatter/**", samples.put)
    node = Node(connect(), "talker")
    publisher = node.create_publisher("std_msgs/msg/String", "/chatter")
    assert node.session.graph_cache().wait_for(lambda g: True, 0)  # graph cache running
    before = time.time_ns()
    # Publish until the raw subscriber's declaration has reached the publisher and a sample arrives.
    deadline, published = time.monotonic() + 10, 0
    while samples.empty() and time.monotonic() < deadline:
        publisher.publish({"data": "hello from rmwz"})
        published += 1
        time.sleep(0.05)
    sample = samples.get(timeout=5)
    subscriber.undeclare()

    assert str(sample.key_expr) == f"0/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}"
    # From the reference capture: CDR_LE header, length 16, "hello from rmwz\0".
    assert sample.payload.to_bytes() == bytes.fromhex("000100001000000068656c6c6f2066726f6d20726d777a00")
    attachment = sample.attachment.to_bytes()
    assert len(attachment) == 33
    sequence, stamp = struct.unpack_from("<qq", attachment)
    assert 1 <= sequence <= published  # the publisher's count of messages, from 1 (earlier ones may be lost)
    assert before <= stamp <= time.time_ns()
    assert attachment[16] == 16
    assert attachment[17:] == publisher.gid


def test_service_reply_echoes_sequence_and_gid_of_a_hand_made_request(
    connect: Callable[[], Session], spy: zenoh.Session
) -> None:
    Node(connect(), "adder").create_service(
        "example_interfaces/srv/AddTwoInts", "/add_two_ints", lambda request: {"sum": request.a + request.b}
    )
    key = f"0/add_two_ints/example_interfaces::srv::dds_::AddTwoInts_/{ADD_HASH}"
    request = bytes.fromhex("00010000") + struct.pack("<qq", 5, 37)
    client_gid = bytes(range(0xA0, 0xB0))
    attachment = struct.pack("<qqB", 77, time.time_ns(), 16) + client_gid
    replies: list[zenoh.Reply] = []
    deadline = time.monotonic() + 5
    while not replies and time.monotonic() < deadline:
        # ALL_COMPLETE only reaches queryables declared complete, as rmw_zenoh's clients require.
        replies = list(
            spy.get(
                key,
                payload=request,
                attachment=attachment,
                target=zenoh.QueryTarget.ALL_COMPLETE,
                consolidation=zenoh.ConsolidationMode.NONE,
                timeout=2,
            )
        )
    assert len(replies) == 1 and replies[0].ok is not None
    reply = replies[0].ok
    assert reply.payload.to_bytes() == bytes.fromhex("00010000") + struct.pack("<q", 42)
    echoed = reply.attachment.to_bytes()
    assert len(echoed) == 33
    assert struct.unpack_from("<q", echoed)[0] == 77
    assert echoed[16] == 16 and echoed[17:] == client_gid


def test_liveliness_tokens_describe_nodes_and_endpoints(
    connect: Callable[[], Session], spy: zenoh.Session
) -> None:
    session = connect()
    server = Node(session, "objective_server")
    server.create_service("example_interfaces/srv/AddTwoInts", "/add_two_ints", lambda r: {"sum": 0})
    server.create_publisher("std_msgs/msg/String", "/chatter")
    server.create_subscription("std_msgs/msg/String", "/chatter", lambda m: None)
    server.create_publisher("std_msgs/msg/String", "/snapshot", latched=True)
    Node(session, "camera", namespace="/robot1").create_publisher("std_msgs/msg/String", "status")
    zid = session.zid
    node = f"@ros2_lv/0/{zid}/{server.node_id}/{server.node_id}/NN/%/%/objective_server"
    tokens = _tokens(spy, lambda t: node in t and sum(1 for x in t if zid in x) >= 7)
    assert node in tokens
    mine = [t.split("/", 4)[4] for t in tokens if t.startswith(f"@ros2_lv/0/{zid}/{server.node_id}/")]
    expected_suffixes = {
        f"SS/%/%/objective_server/%add_two_ints/example_interfaces::srv::dds_::AddTwoInts_/{ADD_HASH}/{DEFAULT_QOS}",
        f"MP/%/%/objective_server/%chatter/std_msgs::msg::dds_::String_/{STRING_HASH}/{DEFAULT_QOS}",
        f"MS/%/%/objective_server/%chatter/std_msgs::msg::dds_::String_/{STRING_HASH}/{DEFAULT_QOS}",
        f"MP/%/%/objective_server/%snapshot/std_msgs::msg::dds_::String_/{STRING_HASH}/{LATCHED_QOS}",
    }
    # "<entity id>/<rest>": the entity ids are distinct numbers.
    assert {entry.split("/", 1)[1] for entry in mine} - {"NN/%/%/objective_server"} == expected_suffixes
    ids = [int(entry.split("/", 1)[0]) for entry in mine]
    assert len(set(ids)) == len(ids)
    assert any(
        t.endswith(
            f"/MP/%/%robot1/camera/%robot1%status/std_msgs::msg::dds_::String_/{STRING_HASH}/{DEFAULT_QOS}"
        )
        for t in tokens
    )


def test_action_server_declares_what_rcl_needs(connect: Callable[[], Session], spy: zenoh.Session) -> None:
    session = connect()
    Node(session, "fib").create_action_server(
        "example_interfaces/action/Fibonacci", "/fibonacci", lambda handle: {"sequence": []}
    )
    tokens = _tokens(spy, lambda t: sum(1 for x in t if "%fibonacci%_action%" in x) >= 5)
    parts = {tuple(t.split("/")[5:12]) for t in tokens if "%fibonacci%_action%" in t}
    kinds = {(p[0], p[4]) for p in parts}
    assert kinds == {
        ("SS", "%fibonacci%_action%send_goal"),
        ("SS", "%fibonacci%_action%cancel_goal"),
        ("SS", "%fibonacci%_action%get_result"),
        ("MP", "%fibonacci%_action%feedback"),
        ("MP", "%fibonacci%_action%status"),
    }
    by_name = {p[4].rsplit("%", 1)[1]: (p[5], p[6]) for p in parts}
    assert by_name["send_goal"][0] == "example_interfaces::action::dds_::Fibonacci_SendGoal_"
    assert by_name["get_result"][0] == "example_interfaces::action::dds_::Fibonacci_GetResult_"
    assert by_name["cancel_goal"][0] == "action_msgs::srv::dds_::CancelGoal_"
    assert by_name["feedback"] == (
        "example_interfaces::action::dds_::Fibonacci_FeedbackMessage_",
        FEEDBACK_HASH,
    )
    assert by_name["status"] == ("action_msgs::msg::dds_::GoalStatusArray_", STATUS_HASH)
    status_token = next(t for t in tokens if "%fibonacci%_action%status" in t)
    assert status_token.endswith(f"/{LATCHED_QOS}")
