"""Loading XML: document rules, errors with file:line, main-tree choice, includes, metadata."""

from __future__ import annotations

from pathlib import Path

import pytest

from kinema.bt import BehaviorTreeFactory, BTError, NodeStatus
from kinema.errors import ObjectiveError

S = NodeStatus.SUCCESS
COMPAT = Path(__file__).resolve().parents[4] / "shared" / "compat" / "moveit_pro" / "objectives"


@pytest.mark.parametrize(
    ("xml", "message"),
    [
        ('<tree><BehaviorTree ID="M"><AlwaysSuccess/></BehaviorTree></tree>', "root node called <root>"),
        ('<root><BehaviorTree ID="M"><Unknown/></BehaviorTree></root>', "Node not recognized: Unknown"),
        (
            '<root><BehaviorTree ID="M"><AlwaysSuccess/><AlwaysFailure/></BehaviorTree></root>',
            "exactly 1 child",
        ),
        ('<root><BehaviorTree ID="M"><Inverter/></BehaviorTree></root>', "must have exactly 1 child"),
        ('<root><BehaviorTree ID="M"><Sequence/></BehaviorTree></root>', "1 or more children"),
        (
            '<root><BehaviorTree ID="M"><AlwaysSuccess><AlwaysSuccess/></AlwaysSuccess></BehaviorTree></root>',  # noqa: E501
            "must not have any child",
        ),
        (
            '<root><BehaviorTree ID="M"><TryCatch><AlwaysSuccess/></TryCatch></BehaviorTree></root>',
            "at least 2",
        ),
        ('<root><BehaviorTree ID="M"><AlwaysSuccess ID="x"/></BehaviorTree></root>', "not allowed in"),
        ('<root><BehaviorTree ID="M"><Action/></BehaviorTree></root>', "must have the attribute [ID]"),
        ('<root><BehaviorTree ID="Sequence"><AlwaysSuccess/></BehaviorTree></root>', "registered Node"),
        ('<root><BehaviorTree ID="M"><AlwaysSuccess da_port="1"/></BehaviorTree></root>', "providedPorts"),
        (
            '<root><BehaviorTree ID="M"><AlwaysSuccess _skipIf="1 +"/></BehaviorTree></root>',
            "Error in the script",
        ),
        ('<root><BehaviorTree ID="M"><Script code="a :="/></BehaviorTree></root>', "Error in the script"),
        (
            '<root><TreeNodesModel/><TreeNodesModel/><BehaviorTree ID="M"><AlwaysSuccess/></BehaviorTree></root>',  # noqa: E501
            "single node <TreeNodesModel>",
        ),
        ("<root><BehaviorTree><AlwaysSuccess/></BehaviorTree><TreeNodesModel/></root>", "attribute [ID]"),
        (
            '<root><BehaviorTree ID="M"><ReactiveSequence><AsyncSequence><AlwaysSuccess/></AsyncSequence>'
            "<AsyncSequence><AlwaysSuccess/></AsyncSequence></ReactiveSequence></BehaviorTree></root>",
            "more than one async child",
        ),
        (
            '<root><BehaviorTree ID="M"><ReactiveSequence><Action ID="AlwaysSuccess"/></ReactiveSequence>'
            "</BehaviorTree></root>",
            "Unknown node type: Action",
        ),
        ('<root><BehaviorTree ID="M"><SubTree ID="Nowhere"/></BehaviorTree></root>', "Nowhere"),
        ("<root><BehaviorTree ID=\"M\"><AlwaysSuccess name='x\x01'/></BehaviorTree></root>", ""),
    ],
)
def test_document_errors(xml: str, message: str) -> None:
    with pytest.raises(ObjectiveError) as info:
        BehaviorTreeFactory().create_tree_from_text(xml)
    assert message in str(info.value)


@pytest.mark.parametrize("comment", ["", "<!-- a comment makes the walk list each node's children -->"])
def test_a_reactive_sequence_is_checked_by_its_own_children(comment: str) -> None:
    # Two ReactiveSequences alike in all but their children's tags: only the second one is wrong.
    async_child = "<AsyncSequence><AlwaysSuccess/></AsyncSequence>"
    xml = (
        '<root BTCPP_format="4">\n<BehaviorTree ID="M">\n<Sequence>\n'
        f"<ReactiveSequence>{async_child}<Sequence><AlwaysSuccess/></Sequence></ReactiveSequence>\n"
        f"<ReactiveSequence>{async_child}{comment}{async_child}</ReactiveSequence>\n"
        "</Sequence>\n</BehaviorTree>\n</root>"
    )
    with pytest.raises(ObjectiveError) as info:
        BehaviorTreeFactory().create_tree_from_text(xml)
    assert str(info.value).startswith("<string>:5: ")  # the line once: BT.CPP's text is in .message
    assert info.value.message.startswith("Error at line 5: ")
    assert "more than one async child" in str(info.value)


@pytest.mark.parametrize("comment", ["", "<!-- a comment makes the walk list each node's children -->"])
@pytest.mark.parametrize(
    ("good", "bad", "message"),
    [
        (
            "<Inverter><AlwaysSuccess/></Inverter>",
            "<Inverter><AlwaysSuccess/>{comment}<AlwaysSuccess/></Inverter>",
            "'Inverter' must have exactly 1 child",
        ),
        ("<AlwaysSuccess/>", "<AlwaysSuccess>{comment}<AlwaysSuccess/></AlwaysSuccess>", "must not have"),
        ('<Action ID="AlwaysSuccess"/>', '<Action ID="Nowhere"/>{comment}', "Node not recognized: Nowhere"),
    ],
)
def test_a_node_like_one_already_checked_is_checked_again_where_it_differs(
    good: str, bad: str, message: str, comment: str
) -> None:
    xml = (
        '<root BTCPP_format="4">\n<BehaviorTree ID="M">\n<Sequence>\n'
        f"{good}\n{bad.format(comment=comment)}\n</Sequence>\n</BehaviorTree>\n</root>"
    )
    with pytest.raises(ObjectiveError) as info:
        BehaviorTreeFactory().create_tree_from_text(xml)
    assert str(info.value).startswith("<string>:5: ")
    assert info.value.message.startswith("Error at line 5: ")
    assert message in str(info.value)


def test_errors_carry_file_and_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.xml"
    path.write_text(
        '<root BTCPP_format="4">\n  <BehaviorTree ID="M">\n    <Nope/>\n  </BehaviorTree>\n</root>\n'
    )
    with pytest.raises(BTError) as info:
        BehaviorTreeFactory().create_tree_from_file(path)
    assert str(info.value).startswith(f"{path}:3: ")


def test_a_missing_closing_tag_names_the_open_element_and_both_lines(tmp_path: Path) -> None:
    """libxml2 says "Opening and ending tag mismatch: Sequence line 3 and BehaviorTree" at line 5: a user read
    the two line numbers as one mistake; the message says which element is left open, and where."""
    path = tmp_path / "unclosed.xml"
    path.write_text(
        '<root BTCPP_format="4">\n  <BehaviorTree ID="M">\n    <Sequence>\n      <AlwaysSuccess/>\n'
        "  </BehaviorTree>\n</root>\n"
    )
    with pytest.raises(ObjectiveError) as info:
        BehaviorTreeFactory().create_tree_from_file(path)
    assert str(info.value) == (
        f"{path}:5: XML syntax error: </BehaviorTree> here, while <Sequence> of line 3 is still open: its "
        "closing tag is missing or misspelt"
    )


def test_lenient_attribute_values() -> None:
    xml = (
        '<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence><Script code="A := 1; B := 2"/>'
        '<ScriptCondition code="A<2 && B>1"/><Script code="C := 3;\n D := 4"/></Sequence></BehaviorTree></root>'  # noqa: E501
    )
    tree = BehaviorTreeFactory().create_tree_from_text(xml)
    assert tree.tick_once() is S
    assert tree.root_blackboard.get("D") == 4


def test_explicit_and_compact_forms_are_equivalent_and_the_tag_is_not_checked() -> None:
    xml = (
        '<root BTCPP_format="4"><BehaviorTree ID="M"><Control ID="Sequence">'
        '<Condition ID="AlwaysSuccess"/><Decorator ID="Inverter"><Action ID="AlwaysFailure"/></Decorator>'
        "</Control></BehaviorTree></root>"
    )
    assert BehaviorTreeFactory().create_tree_from_text(xml).tick_once() is S


def test_main_tree_choice() -> None:
    factory = BehaviorTreeFactory()
    two = (
        '<root main_tree_to_execute="B"><BehaviorTree ID="A"><AlwaysFailure/></BehaviorTree>'
        '<BehaviorTree ID="B"><AlwaysSuccess/></BehaviorTree></root>'
    )
    assert factory.create_tree_from_text(two).tick_once() is S
    anonymous = "<root><BehaviorTree><AlwaysSuccess/></BehaviorTree></root>"
    tree = factory.create_tree_from_text(anonymous)
    assert tree.subtrees[0].tree_id == "BehaviorTree_0"
    assert sorted(factory.registered_behavior_trees()) == ["A", "B", "BehaviorTree_0"]


def test_trees_registered_earlier_are_visible_to_later_documents() -> None:
    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(
        '<root><BehaviorTree ID="Lib"><AlwaysSuccess/></BehaviorTree></root>'
    )
    tree = factory.create_tree_from_text(
        '<root><BehaviorTree ID="M"><SubTree ID="Lib"/></BehaviorTree></root>'
    )
    assert tree.tick_once() is S
    factory.register_behavior_tree_from_text(
        '<root><BehaviorTree ID="Lib"><AlwaysFailure/></BehaviorTree></root>'
    )
    assert factory.create_tree("M").tick_once() is NodeStatus.FAILURE  # reloading replaces
    factory.clear_registered_behavior_trees()
    assert factory.registered_behavior_trees() == []


def test_includes_resolve_relative_to_the_including_file(tmp_path: Path) -> None:
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "inner.xml").write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Inner"><AlwaysSuccess/></BehaviorTree></root>'
    )
    (tmp_path / "lib" / "middle.xml").write_text(
        '<root BTCPP_format="4"><include path="inner.xml"/>'
        '<BehaviorTree ID="Middle"><SubTree ID="Inner"/></BehaviorTree></root>'
    )
    main = tmp_path / "main.xml"
    main.write_text(
        '<root BTCPP_format="4" main_tree_to_execute="Main"><include path="lib/middle.xml"/>'
        '<BehaviorTree ID="Main"><SubTree ID="Middle"/></BehaviorTree></root>'
    )
    assert BehaviorTreeFactory().create_tree_from_file(main).tick_once() is S


def test_an_include_cycle_is_reported(tmp_path: Path) -> None:
    (tmp_path / "a.xml").write_text('<root><include path="b.xml"/></root>')
    (tmp_path / "b.xml").write_text('<root><include path="a.xml"/></root>')
    with pytest.raises(BTError, match="cycle"):
        BehaviorTreeFactory().register_behavior_tree_from_file(tmp_path / "a.xml")


def test_metadata_is_kept_for_writing_objectives_back() -> None:
    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Pick" _description="Pick it" _favorite="true">'
        '<Sequence _collapsed="true"><AlwaysSuccess/></Sequence></BehaviorTree>'
        '<TreeNodesModel><SubTree ID="Pick"><input_port name="speed" default="1.0" description="how fast"/>'
        '<MetadataFields><Metadata subcategory="Grasping"/><Metadata runnable="true"/></MetadataFields>'
        "</SubTree></TreeNodesModel></root>"
    )
    definition = factory.tree_definition("Pick")
    assert definition.attributes == {"ID": "Pick", "_description": "Pick it", "_favorite": "true"}
    assert 'Sequence _collapsed="true"' in definition.to_xml()
    model = factory.library.subtree_models["Pick"]
    assert model.metadata == [("subcategory", "Grasping"), ("runnable", "true")]
    assert model.ports["speed"].default_str == "1.0" and model.ports["speed"].description == "how fast"
    tree = factory.create_tree("Pick")
    assert tree.root_node.config.other_attributes == {"_collapsed": "true"}  # type: ignore[union-attr]


def test_deep_nesting_is_reported_not_crashed() -> None:
    depth = 300
    body = "<Inverter>" * depth + "<AlwaysFailure/>" + "</Inverter>" * depth
    with pytest.raises(ObjectiveError, match=r"deeper than 256|nesting depth"):
        BehaviorTreeFactory().create_tree_from_text(
            f'<root><BehaviorTree ID="M">{body}</BehaviorTree></root>'
        )


@pytest.mark.skipif(
    not COMPAT.is_dir(), reason="the MoveIt Pro compatibility files are not beside the checkout"
)
def test_moveit_pro_objectives_load_into_the_library() -> None:
    factory = BehaviorTreeFactory()
    for path in sorted(COMPAT.glob("*.xml")):
        factory.library.load_file(path, factory.manifests(), verify=False)
    assert {"Move to Waypoint", "Move to Joint State", "3 Waypoints Pick and Place"} <= set(
        factory.registered_behavior_trees()
    )
    assert factory.tree_definition("Open Gripper").attributes["_description"] == "Open the gripper"


def test_objectives_are_written_back_with_their_metadata() -> None:
    from kinema.bt import write_objective_xml

    source = (
        '<root BTCPP_format="4" main_tree_to_execute="Pick">'
        '<BehaviorTree ID="Pick" _description="Pick &amp; place" _favorite="true">'
        '<Sequence _collapsed="true"><!-- keep me --><Script code="a := 1&#10;b := a &lt; 2"/>'
        '<SubTree ID="Helper" speed="{s}"/></Sequence></BehaviorTree>'
        '<BehaviorTree ID="Helper"><AlwaysSuccess/></BehaviorTree>'
        '<TreeNodesModel><SubTree ID="Helper"><input_port name="speed" default="1.0" description="how fast"/>'
        '<MetadataFields><Metadata subcategory="Motion"/></MetadataFields></SubTree></TreeNodesModel></root>'
    )
    factory = BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(source)
    written = write_objective_xml(factory, ["Pick", "Helper"], main_tree="Pick")
    again = BehaviorTreeFactory()
    again.register_behavior_tree_from_text(written)
    assert again.tree_definition("Pick").attributes == factory.tree_definition("Pick").attributes
    assert "keep me" in written and '_collapsed="true"' in written
    script = again.tree_definition("Pick").element.find(".//Script")
    assert script is not None and script.get("code") == "a := 1\nb := a < 2"
    model = again.library.subtree_models["Helper"]
    assert model.metadata == [("subcategory", "Motion")] and model.ports["speed"].description == "how fast"
    tree = again.create_tree_from_text(written)
    assert tree.tick_once() is S


def test_an_instance_name_with_a_control_character_is_refused_at_its_line() -> None:
    # XML itself refuses most control characters; DEL reaches the name check, tab is a valid name.
    document = '<root><BehaviorTree ID="T">\n<AlwaysSuccess name="{}"/></BehaviorTree></root>'
    with pytest.raises(BTError, match=r"invalid control character \(ASCII 127\)") as caught:
        BehaviorTreeFactory().create_tree_from_text(document.format("arm\x7f1"))
    assert caught.value.location is not None and caught.value.location.line == 2
    BehaviorTreeFactory().create_tree_from_text(document.format("arm&#9;1"))


def test_an_unknown_node_names_its_line_once_and_the_registered_names_close_to_it() -> None:
    xml = (
        '<root BTCPP_format="4">\n<BehaviorTree ID="M">\n<Sequence>\n<AlwaysSucess/>\n'
        "</Sequence>\n</BehaviorTree>\n</root>"
    )
    with pytest.raises(ObjectiveError) as info:
        BehaviorTreeFactory().create_tree_from_text(xml)
    assert str(info.value).startswith(
        "<string>:4: Node not recognized: AlwaysSucess; did you mean 'AlwaysSuccess'"
    )
    assert "Error at line" not in str(info.value)
