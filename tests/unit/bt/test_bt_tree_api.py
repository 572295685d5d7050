"""The Tree and factory API other parts of Kinema build on."""

from __future__ import annotations

import threading
import time

import pytest
from lxml import etree

from kinema.bt import (
    BehaviorTreeFactory,
    BTError,
    BTLogicError,
    ConditionNode,
    ManualClock,
    NodeConfig,
    NodeExecutionError,
    NodeStatus,
    NodeType,
    StatefulActionNode,
    SyncActionNode,
    TreeObserver,
    bidirectional_port,
    input_port,
    output_port,
    write_tree_nodes_model_xml,
)
from kinema.bt.builtins import BUILTIN_NODE_TYPES

S, F, R, IDLE = NodeStatus.SUCCESS, NodeStatus.FAILURE, NodeStatus.RUNNING, NodeStatus.IDLE


def test_status_observer_sees_every_change_including_resets(bench) -> None:
    tree = bench.tree('<Sequence name="seq"><AlwaysSuccess name="a"/></Sequence>')
    changes = []
    handle = tree.add_status_observer(lambda t, node, prev, new: changes.append((node.full_path, prev, new)))
    tree.tick_once()
    assert changes == [("seq", IDLE, R), ("a", IDLE, S), ("a", S, IDLE), ("seq", R, S), ("seq", S, IDLE)]
    tree.remove_status_observer(handle)
    tree.tick_once()
    assert len(changes) == 5


def test_tree_observer_statistics(bench) -> None:
    bench.condition("Check", F, F, S)
    tree = bench.tree('<RetryUntilSuccessful num_attempts="5"><Check name="check"/></RetryUntilSuccessful>')
    observer = TreeObserver(tree)
    assert tree.tick_once() is S
    stats = observer.statistics("check")
    assert (stats.failure_count, stats.success_count, stats.transitions_count) == (2, 1, 3)
    assert stats.last_result is S
    assert observer.statistics(tree.node_by_path("check").uid) is stats
    with pytest.raises(BTError, match="no node with path"):
        observer.statistics("nope")


def test_halt_tree_runs_on_halted_everywhere_and_halts_running_nodes(bench) -> None:
    bench.stateful("Work", running_ticks=-1)
    tree = bench.tree(
        '<Sequence><Script code="h := 0"/><AlwaysSuccess _onHalted="h += 1"/><Work _onHalted="h += 10"/></Sequence>'  # noqa: E501
    )
    assert tree.tick_once() is R
    tree.halt_tree()
    assert bench.halts["Work"] == 1
    assert tree.root_blackboard.get("h") == 21  # halted twice counts as in BT.CPP: root halt, then every node
    assert all(node.status is IDLE for node in tree.nodes())


def test_exceptions_are_wrapped_once_with_the_innermost_node(bench) -> None:
    class Broken(SyncActionNode):
        def tick(self) -> NodeStatus:
            raise ValueError("sensor unplugged")

    bench.factory.register_node_type(Broken, "Broken")
    tree = bench.tree('<Sequence><Inverter><Broken name="camera"/></Inverter></Sequence>')
    with pytest.raises(NodeExecutionError) as info:
        tree.tick_once()
    assert info.value.node_path == "camera"
    assert str(info.value).endswith("Exception in node 'camera' [Broken]: ValueError: sensor unplugged")


def test_sync_action_may_not_return_running(bench) -> None:
    class Liar(SyncActionNode):
        def tick(self) -> NodeStatus:
            return R

    bench.factory.register_node_type(Liar, "Liar")
    with pytest.raises(BTLogicError, match="never return RUNNING"):
        bench.tree("<Liar/>").tick_once()
    bench.factory.register_simple_action("Simple", lambda node: R)
    with pytest.raises(BTLogicError):
        bench.tree("<Simple/>").tick_once()


def test_stateful_action_lifecycle(bench) -> None:
    calls = []

    class Move(StatefulActionNode):
        @classmethod
        def provided_ports(cls) -> list:
            return [input_port("steps", int, 2), output_port("done", bool)]

        def on_start(self) -> NodeStatus:
            calls.append("start")
            self.left = self.get_input("steps")
            return R

        def on_running(self) -> NodeStatus:
            calls.append("running")
            self.left -= 1
            if self.left == 0:
                self.set_output("done", True)
                return S
            return R

        def on_halted(self) -> None:
            calls.append("halted")

    bench.factory.register_node_type(Move, "Move")
    tree = bench.tree('<Move done="{finished}"/>')
    assert [tree.tick_once() for _ in range(3)] == [R, R, S]
    assert calls == ["start", "running", "running"]
    assert tree.root_blackboard.get("finished") is True
    tree.tick_once()
    tree.halt_tree()
    assert calls[-1] == "halted"


def test_registration_rules() -> None:
    factory = BehaviorTreeFactory()

    class Bad(ConditionNode):
        @classmethod
        def provided_ports(cls) -> list:
            return [input_port("name")]

    with pytest.raises(BTLogicError, match="reserved"):
        factory.register_node_type(Bad, "Bad")
    with pytest.raises(BTLogicError, match="already registered"):
        factory.register_simple_action("Sequence", lambda n: S)
    with pytest.raises(BTLogicError, match="forbidden character"):
        factory.register_simple_action("has space", lambda n: S)
    factory.register_simple_condition("Ok", lambda n: S)
    assert factory.manifests()["Ok"].category is NodeType.CONDITION
    assert factory.unregister("Ok") and not factory.is_registered("Ok")


def test_a_node_that_drops_its_config_or_a_builder_that_returns_no_node_fails_the_build_at_its_line() -> None:
    factory = BehaviorTreeFactory()

    class Forgetful(SyncActionNode):
        def __init__(self, name: str, config: object) -> None:
            super().__init__(name)  # its own config, not the builder's

        def tick(self) -> NodeStatus:
            return S

    factory.register_node_type(Forgetful, "Forgetful")
    from kinema.bt.manifest import NodeManifest

    factory.register_builder(NodeManifest("NotANode", NodeType.ACTION), lambda name, config: "a string")
    for node_id, message in (("Forgetful", "must pass its config"), ("NotANode", "not a TreeNode")):
        tree = f'<BehaviorTree ID="T">\n<Sequence>\n<{node_id}/></Sequence></BehaviorTree>'
        xml = f'<root BTCPP_format="4">{tree}</root>'
        with pytest.raises(BTLogicError, match=message) as caught:
            factory.create_tree_from_text(xml)
        assert caught.value.location is not None and caught.value.location.line == 3


def test_each_node_owns_its_config_dicts(bench) -> None:
    # Empty ones are made on first use, each node its own; what the XML gave is each node's copy.
    tree = bench.tree(
        '<Sequence><AlwaysSuccess name="a"/><AlwaysSuccess name="b"/>'
        '<AlwaysSuccess name="c" _note="x" _onSuccess="done := 1"/>'
        '<AlwaysSuccess name="d" _note="x" _onSuccess="done := 1"/>'
        "</Sequence>"
    )
    a, b, c, d = (tree.node_by_path(name).config for name in "abcd")
    for name in ("other_attributes", "pre_conditions", "post_conditions", "input_ports", "output_ports"):
        assert getattr(a, name) == {} and getattr(a, name) is not getattr(b, name), name
        assert getattr(a, name) is getattr(a, name), name
    a.other_attributes["_note"] = "mine"
    a.post_conditions["_onSuccess"] = c.post_conditions["_onSuccess"]
    assert b.other_attributes == {} and b.post_conditions == {}
    assert c.other_attributes == d.other_attributes == {"_note": "x"}
    c.other_attributes["_note"] = "changed"
    assert d.other_attributes == {"_note": "x"}
    assert tree.tick_once() is S
    assert tree.root_blackboard.get("done") == 1
    fresh = NodeConfig()
    assert fresh.pre_conditions == fresh.post_conditions == fresh.other_attributes == {}
    fresh.other_attributes = {"k": "v"}
    assert fresh.other_attributes == {"k": "v"}


def test_every_factory_gets_the_same_builtin_models_and_owns_them() -> None:
    # Later factories copy what the first one read from the classes; each owns its manifests.
    first, second = BehaviorTreeFactory(), BehaviorTreeFactory()
    assert second._builders == first._builders == BUILTIN_NODE_TYPES
    assert write_tree_nodes_model_xml(second, include_builtin=True) == write_tree_nodes_model_xml(
        first, include_builtin=True
    )
    second.manifests()["Sequence"].description = "changed"
    second.manifests()["Timeout"].ports.pop("msec")
    third = BehaviorTreeFactory()
    assert third.manifests()["Sequence"].description == first.manifests()["Sequence"].description
    assert "msec" in third.manifests()["Timeout"].ports
    assert third.manifests()["SubTree"].category is NodeType.SUBTREE


def test_builtin_ids_match_btcpp_4_10() -> None:
    builtin = set(BehaviorTreeFactory().builtin_nodes())
    assert len(builtin) == 42
    assert {"TryCatch", "Switch6", "LoopString", "WaitValueUpdate", "WasEntryUpdated", "SubTree"} <= builtin
    assert "ManualSelector" not in builtin and "SequenceStar" not in builtin


def test_tree_nodes_model_export() -> None:
    factory = BehaviorTreeFactory()

    class Gripper(StatefulActionNode):
        """Open or close the gripper."""

        @classmethod
        def provided_ports(cls) -> list:
            return [
                input_port("position", float, 0.5, "target opening"),
                output_port("reached", bool),
                bidirectional_port("queue"),
            ]

        @classmethod
        def metadata(cls) -> dict[str, str]:
            return {"subcategory": "Grasping"}

    factory.register_node_type(Gripper, "MoveGripper")
    root = etree.fromstring(write_tree_nodes_model_xml(factory).encode())
    (model,) = root.find("TreeNodesModel")
    assert (model.tag, model.get("ID")) == ("Action", "MoveGripper")
    ports = {p.get("name"): p for p in model if p.tag.endswith("_port")}
    assert ports["position"].attrib == {"name": "position", "type": "double", "default": "0.500000"}
    assert ports["position"].text == "target opening"
    assert ports["reached"].tag == "output_port" and ports["queue"].get("type") == "BT::AnyTypeAllowed"
    assert model.find("MetadataFields/Metadata").attrib == {"subcategory": "Grasping"}
    full = etree.fromstring(write_tree_nodes_model_xml(factory, include_builtin=True).encode())
    ids = [m.get("ID") for m in full.find("TreeNodesModel")]
    assert ids == sorted(ids) and "Sequence" in ids


def test_tree_sleep_returns_early_on_wake_up(bench) -> None:
    tree = bench.tree("<AlwaysSuccess/>")
    threading.Timer(0.05, tree.wake_up.emit).start()
    start = time.monotonic()
    assert tree.sleep(5.0) is True
    assert time.monotonic() - start < 4.0
    assert tree.sleep(0.01) is False


def test_sleep_on_a_manual_clock_waits_for_simulated_time() -> None:
    clock = ManualClock()
    tree = BehaviorTreeFactory(clock=clock).create_tree_from_text(
        '<root><BehaviorTree ID="M"><AlwaysSuccess/></BehaviorTree></root>'
    )
    done = threading.Event()
    threading.Thread(target=lambda: (tree.sleep(2.0), done.set()), daemon=True).start()
    # Advance only once the sleeper's timer is set (a starved thread may take a while to get there).
    deadline = time.monotonic() + 30.0
    while not clock._heap and time.monotonic() < deadline:
        time.sleep(0.005)
    time.sleep(0.05)
    assert not done.is_set()  # 0.05 s of wall time and none of the clock's: still asleep
    clock.advance(2.0)
    assert done.wait(5.0)


def test_tick_while_running_skipped_root_stays_idle(bench) -> None:
    tree = bench.tree('<AlwaysSuccess _skipIf="true"/>')
    assert tree.tick_while_running() is NodeStatus.SKIPPED
    assert tree.root_node.status is IDLE  # type: ignore[union-attr]


def test_blackboard_snapshot_and_tree_observer_of_writes(bench) -> None:
    bench.factory.register_behavior_tree_from_text(
        '<root><BehaviorTree ID="Main"><Sequence><Script code="x := 1"/><SubTree ID="S" name="sub"/></Sequence>'  # noqa: E501
        '</BehaviorTree><BehaviorTree ID="S"><Script code="y := 2.5"/></BehaviorTree></root>'
    )
    tree = bench.factory.create_tree("Main")
    writes = []
    tree.add_blackboard_observer(lambda scope, key, entry: writes.append((scope, key, entry.value)))
    tree.tick_once()
    assert writes == [("Main", "x", 1), ("sub", "y", 2.5)]
    assert tree.blackboard_snapshot() == {"Main": {"x": ("int", 1)}, "sub": {"y": ("double", 2.5)}}


def test_walk_visits_nodes_depth_first_with_depth(bench) -> None:
    tree = bench.tree('<Sequence name="s"><Inverter name="i"><AlwaysFailure name="f"/></Inverter></Sequence>')
    assert [(n.name, d) for n, d in tree.walk()] == [("s", 0), ("i", 1), ("f", 2)]
    assert len(tree) == 3 and [n.name for n in tree] == ["s", "i", "f"]


def test_pre_and_post_tick_callbacks_substitute_results(bench) -> None:
    bench.action("Real", F)
    tree = bench.tree('<Sequence><Real name="real"/><AlwaysSuccess name="after"/></Sequence>')
    real = tree.node_by_path("real")
    real.set_pre_tick_callback(lambda node: S)
    assert tree.tick_once() is S
    assert bench.ticks["Real"] == 0  # the substitution skipped tick()
    real.set_pre_tick_callback(None)
    real.set_post_tick_callback(lambda node, status: S if status is F else status)
    assert tree.tick_once() is S
    assert bench.ticks["Real"] == 1
    real.set_post_tick_callback(None)
    assert tree.tick_once() is F


def test_write_tree_to_xml_matches_btcpp_layout(bench) -> None:
    from kinema.bt import write_tree_to_xml

    bench.factory.register_behavior_tree_from_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Main"><Sequence name="root_seq"><Script code="x := 1"/>'
        '<SubTree ID="Sub" name="sub1" v="{x}"/><Sleep msec="20" _skipIf="x == 2"/></Sequence></BehaviorTree>'
        '<BehaviorTree ID="Sub"><Fallback><AlwaysFailure/><AlwaysSuccess name="ok"/></Fallback></BehaviorTree>'  # noqa: E501
        "</root>"
    )
    root = etree.fromstring(
        write_tree_to_xml(bench.factory.create_tree("Main"), add_builtin_models=False).encode()
    )
    main, sub = root.findall("BehaviorTree")
    assert (main.get("ID"), main.get("_fullpath"), sub.get("ID"), sub.get("_fullpath")) == (
        "Main",
        "",
        "Sub",
        "sub1",
    )
    assert [(e.tag, e.get("name"), e.get("_uid")) for e in main.iter() if e is not main] == [
        ("Sequence", "root_seq", "1"),
        ("Script", "Script", "2"),
        ("SubTree", None, "3"),
        ("Sleep", "Sleep", "7"),
    ]
    subtree_call = main.find(".//SubTree")
    assert subtree_call.attrib == {"ID": "Sub", "_fullpath": "sub1", "_uid": "3", "v": "{x}"}
    assert main.find(".//Sleep").attrib == {"name": "Sleep", "_uid": "7", "msec": "20", "_skipIf": "x == 2"}
    assert [e.get("_uid") for e in sub.iter() if e is not sub] == ["4", "5", "6"]


def _counting_tree(cycles: int):
    factory = BehaviorTreeFactory()
    ticks: list[int] = []

    def count(node):
        ticks.append(len(ticks))
        return S

    factory.register_simple_action("Count", count)
    xml = (
        '<root BTCPP_format="4"><BehaviorTree ID="T">'
        f'<Repeat num_cycles="{cycles}"><Count/></Repeat></BehaviorTree></root>'
    )
    return factory.create_tree_from_text(xml), ticks


def test_tick_once_until_stops_a_self_reticking_tree_and_owes_the_tick() -> None:
    # An endless Repeat of a synchronous child re-ticks itself inside one tick_once forever (as in
    # BT.CPP); ``until`` lets a ticker stop it between iterations.
    tree, ticks = _counting_tree(-1)
    checks = []
    status = tree.tick_once(until=lambda: checks.append(1) or len(checks) >= 3)
    assert status is R and tree.retick_due
    assert len(ticks) == 3
    tree.halt_tree()


def test_tick_once_until_keeps_bt_cpp_results_for_trees_nobody_cancels() -> None:
    # Stopping at every chance and calling tick_once again gives the same ticks and result as one
    # uninterrupted tick_once.
    plain, plain_ticks = _counting_tree(7)
    assert plain.tick_once() is S
    interrupted, interrupted_ticks = _counting_tree(7)
    calls = 0
    status = R
    while status is R:
        calls += 1
        status = interrupted.tick_once(until=lambda: True)
    assert status is S and not interrupted.retick_due
    assert interrupted_ticks == plain_ticks and len(plain_ticks) == 7
    assert calls == 7
