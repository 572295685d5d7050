"""Graph queries: nodes, topics, services and actions with their types; entities leave on close."""

from __future__ import annotations

from collections.abc import Callable

from kinema.transport import Node, Session


def test_graph_lists_everything_with_types(connect: Callable[[], Session]) -> None:
    session = connect()
    server = Node(session, "agent")
    server.create_publisher(
        "moveit_studio_agent_msgs/msg/ObjectiveServerStatus", "/objective_server_heartbeat"
    )
    server.create_service("moveit_studio_sdk_msgs/srv/ExecuteObjective", "/execute_objective", lambda r: {})
    server.create_action_server(
        "moveit_studio_sdk_msgs/action/DoObjectiveSequence", "/do_objective", lambda h: {}
    )
    Node(session, "driver", namespace="sim").create_subscription(
        "sensor_msgs/msg/JointState", "joint_states", print
    )

    observer = Node(connect(), "observer")
    assert observer.session.graph_cache().wait_for(lambda g: "/do_objective" in g.actions(), 5)
    graph = observer.graph(timeout=2)
    assert {"/agent", "/sim/driver", "/observer"} <= set(graph.nodes())
    assert graph.topics()["/objective_server_heartbeat"] == [
        "moveit_studio_agent_msgs/msg/ObjectiveServerStatus"
    ]
    assert graph.topics()["/sim/joint_states"] == ["sensor_msgs/msg/JointState"]
    assert "/do_objective/_action/feedback" not in graph.topics()
    assert "/do_objective/_action/feedback" in graph.topics(hidden=True)
    assert graph.services()["/execute_objective"] == ["moveit_studio_sdk_msgs/srv/ExecuteObjective"]
    assert graph.actions() == {"/do_objective": ["moveit_studio_sdk_msgs/action/DoObjectiveSequence"]}
    assert graph.action_server_ready("/do_objective")


def test_closed_node_disappears_from_the_graph(connect: Callable[[], Session]) -> None:
    leaving = Node(connect(), "leaving")
    leaving.create_service("example_interfaces/srv/AddTwoInts", "/leaving_add", lambda r: {"sum": 0})
    cache = Node(connect(), "observer").session.graph_cache()
    assert cache.wait_for(lambda g: "/leaving" in g.nodes() and "/leaving_add" in g.services(), 5)
    leaving.close()
    assert cache.wait_for(lambda g: "/leaving" not in g.nodes() and "/leaving_add" not in g.services(), 5)
