"""Key expressions, liveliness tokens, QoS strings and name resolution (rmw_zenoh design examples)."""

from __future__ import annotations

import pytest

from kinema.errors import TransportError
from kinema.transport.keys import (
    LATCHED_QOS,
    EntityKind,
    QoS,
    data_key,
    entity_token,
    fully_qualified,
    node_token,
    parse_token,
)

ADD_HASH = "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
ZID = "f9980ee0495eaafb3e38f0d19e2eae12"


def test_service_key_of_the_design_doc() -> None:
    key = data_key(2, "/add_two_ints", "example_interfaces::srv::dds_::AddTwoInts_", ADD_HASH)
    assert key == f"2/add_two_ints/example_interfaces::srv::dds_::AddTwoInts_/{ADD_HASH}"


def test_namespaced_topic_key() -> None:
    assert data_key(0, "/robot1/chatter", "std_msgs::msg::dds_::String_", "RIHS01_x") == (
        "0/robot1/chatter/std_msgs::msg::dds_::String_/RIHS01_x"
    )


def test_service_server_token_of_the_design_doc() -> None:
    token = entity_token(
        2,
        ZID,
        0,
        10,
        EntityKind.SERVICE_SERVER,
        "",
        "add_two_ints_server",
        "/add_two_ints",
        "example_interfaces::srv::dds_::AddTwoInts_",
        ADD_HASH,
        QoS(),
    )
    assert token == (
        f"@ros2_lv/2/{ZID}/0/10/SS/%/%/add_two_ints_server/%add_two_ints/"
        f"example_interfaces::srv::dds_::AddTwoInts_/{ADD_HASH}/::,10:,:,:,,"
    )
    parsed = parse_token(token)
    assert parsed is not None
    assert (parsed.kind, parsed.name, parsed.type_name, parsed.node_fqn) == (
        EntityKind.SERVICE_SERVER,
        "/add_two_ints",
        "example_interfaces/srv/AddTwoInts",
        "/add_two_ints_server",
    )


def test_node_token_with_namespace() -> None:
    token = node_token(0, ZID, 3, "/robot1/arm", "driver")
    assert token == f"@ros2_lv/0/{ZID}/3/3/NN/%/%robot1%arm/driver"
    parsed = parse_token(token)
    assert parsed is not None and parsed.node_fqn == "/robot1/arm/driver"


@pytest.mark.parametrize(
    ("qos", "text"),
    [
        (QoS(), "::,10:,:,:,,"),
        (LATCHED_QOS, ":1:,1:,:,:,,"),
        (QoS(reliable=False, depth=5), "2::,5:,:,:,,"),
        (QoS(keep_all=True), "::2,10:,:,:,,"),
    ],
)
def test_qos_strings(qos: QoS, text: str) -> None:
    assert qos.encode() == text
    assert QoS.decode(text) == qos


@pytest.mark.parametrize(
    ("name", "namespace", "expected"),
    [
        ("chatter", "", "/chatter"),
        ("chatter", "/robot1", "/robot1/chatter"),
        ("/chatter", "/robot1", "/chatter"),
        ("~/status", "/robot1", "/robot1/node/status"),
        ("a//b/", "", "/a/b"),
    ],
)
def test_name_resolution(name: str, namespace: str, expected: str) -> None:
    assert fully_qualified(name, namespace, "node") == expected


@pytest.mark.parametrize("bad", ["", "/has space", "/dash-ed"])
def test_bad_names_are_refused(bad: str) -> None:
    with pytest.raises(TransportError):
        fully_qualified(bad)


def test_foreign_keys_are_not_tokens() -> None:
    assert parse_token("@ros2_lv/0/zid/1/2/XX/%/%/n") is None
    assert parse_token("0/chatter/std_msgs::msg::dds_::String_/RIHS01_x") is None
