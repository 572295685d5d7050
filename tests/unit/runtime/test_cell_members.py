"""Who holds a cell's roles: presence tokens and the ROS graph, and the messages about two of a kind."""

from __future__ import annotations

from types import SimpleNamespace

from kinema.runtime.cell import AGENT, DRIVER, Member, cell_members, conflicts, parse_presence, presence_key
from kinema.transport import Graph
from kinema.transport.keys import EntityKind, GraphEntity


def _entity(zid: str, kind: EntityKind, node: str, name: str = "") -> GraphEntity:
    return GraphEntity(0, zid, "1", "2", kind, "", "", node, name=name)


def test_a_presence_key_round_trips_odd_characters() -> None:
    session = SimpleNamespace(domain_id=3, zid="abc123")
    member = Member(DRIVER, "abc123", "mujoco", 42, 7, "robot-pc.lab", "my_cell", "tcp/[::1]:7447")
    key = presence_key(session, member)  # type: ignore[arg-type]
    assert key.startswith("@kinema_lv/3/abc123/driver/mujoco/42/7/")
    assert all(chunk and not set(chunk) & set("*$?#") for chunk in key.split("/"))
    assert parse_presence(key) == member
    assert parse_presence("@ros2_lv/0/abc/1/1/NN/%/%/node") is None


def test_members_come_from_presences_and_from_the_graph_for_processes_without_one() -> None:
    graph = Graph(
        (
            _entity("a1", EntityKind.NODE, "objective_server"),
            _entity("d1", EntityKind.NODE, "controller_manager"),
            _entity("d1", EntityKind.PUBLISHER, "joint_state_broadcaster", "/joint_states"),
            _entity("ros", EntityKind.PUBLISHER, "robot_driver", "/joint_states"),
            _entity("ui", EntityKind.NODE, "kinema_sdk_1"),
        )
    )
    presences = [Member(DRIVER, "d1", "mujoco", 12, 10, "vm", "lab_sim", "tcp/127.0.0.1:7447")]
    members = cell_members(graph, presences)
    assert [m.zid for m in members[AGENT]] == ["a1"]
    assert [(m.zid, m.name) for m in members[DRIVER]] == [("d1", "mujoco"), ("ros", "")]
    (message,) = conflicts(members)
    assert message.startswith("2 drivers on one network: driver 'mujoco' of config lab_sim (pid 12, host vm")
    assert "driver (zenoh id ros; not a Kinema process or an older one)" in message


def test_one_of_each_is_no_conflict() -> None:
    graph = Graph((_entity("a1", EntityKind.NODE, "objective_server"),))
    assert conflicts(cell_members(graph, [Member(DRIVER, "d1", "mujoco", 3)])) == []
