"""SubTree instances: blackboard scopes, remapping, models, paths and uids (reference §1.7, §5)."""

from __future__ import annotations

import pytest

from kinema.bt import BTError, NodeStatus

S, F = NodeStatus.SUCCESS, NodeStatus.FAILURE


def doc(*trees: str, main: str = "Main", models: str = "") -> str:
    body = "".join(trees) + (f"<TreeNodesModel>{models}</TreeNodesModel>" if models else "")
    return f'<root BTCPP_format="4" main_tree_to_execute="{main}">{body}</root>'


def tree_def(tree_id: str, body: str) -> str:
    return f'<BehaviorTree ID="{tree_id}">{body}</BehaviorTree>'


def test_subtree_scopes_are_isolated_without_remapping(bench) -> None:
    tree = bench.xml(
        doc(
            tree_def("Main", '<Sequence><Script code="x := 1"/><SubTree ID="Sub"/></Sequence>'),
            tree_def("Sub", '<Script code="x := 2; y := 3"/>'),
        )
    )
    assert tree.tick_once() is S
    assert tree.root_blackboard.get("x") == 1
    assert "y" not in tree.root_blackboard
    assert tree.subtrees[1].blackboard.get("x") == 2


@pytest.mark.parametrize("call", ['inner="{outer}"', 'outer="{=}"', '_autoremap="true"'])
def test_remapping_forms(bench, call: str) -> None:
    key = "inner" if "inner" in call else "outer"
    tree = bench.xml(
        doc(
            tree_def("Main", f'<Sequence><Script code="outer := 1"/><SubTree ID="Sub" {call}/></Sequence>'),
            tree_def("Sub", f'<Script code="{key} := {key} + 10"/>'),
        )
    )
    assert tree.tick_once() is S
    assert tree.root_blackboard.get("outer") == 11


def test_literal_attributes_keep_numeric_types(bench) -> None:
    tree = bench.xml(
        doc(
            tree_def(
                "Main",
                '<SubTree ID="Sub" i="42" d="2.5" s="two words" v="1;2;3" big="9999999999" huge="'
                + "9" * 400
                + '"/>',
            ),
            tree_def("Sub", '<ScriptCondition code="i + 1 == 43 &amp;&amp; d * 2 == 5"/>'),
        )
    )
    assert tree.tick_once() is S
    scope = tree.subtrees[1].blackboard
    assert [type(scope.get(k)) for k in ("i", "d", "s", "v", "big", "huge")] == [
        int,
        float,
        str,
        str,
        int,
        str,
    ]


def test_private_keys_are_never_auto_remapped(bench) -> None:
    tree = bench.xml(
        doc(
            tree_def("Main", '<SubTree ID="Sub" _autoremap="true"/>'),
            tree_def("Sub", '<Script code="public := 1; _private := 2"/>'),
        )
    )
    tree.tick_once()
    assert tree.root_blackboard.get("public") == 1
    assert "_private" not in tree.root_blackboard


def test_root_blackboard_from_a_nested_subtree(bench) -> None:
    tree = bench.xml(
        doc(
            tree_def("Main", '<SubTree ID="A"/>'),
            tree_def("A", '<SubTree ID="B"/>'),
            tree_def("B", '<Script code="@deep := 7"/>'),
        )
    )
    tree.tick_once()
    assert tree.root_blackboard.get("deep") == 7


def test_model_defaults_and_mandatory_ports(bench) -> None:
    models = (
        '<SubTree ID="Sub"><input_port name="speed" default="0.5"/>'
        '<output_port name="result" default="{res}"/>'
        '<input_port name="target"/></SubTree>'
    )
    sub = tree_def("Sub", '<Script code="result := speed * 2"/>')
    tree = bench.xml(doc(tree_def("Main", '<SubTree ID="Sub" target="here"/>'), sub, models=models))
    assert tree.tick_once() is S
    assert tree.root_blackboard.get("res") == 1.0
    with pytest.raises(BTError, match=r"mandatory port called \[target\]"):
        bench.xml(doc(tree_def("Main", '<SubTree ID="Sub"/>'), sub, models=models))


def test_paths_and_uids(bench) -> None:
    tree = bench.xml(
        doc(
            tree_def(
                "Main",
                '<Sequence name="root_seq"><Script code="x := 1"/><SubTree ID="Sub" name="sub1"/>'
                '<SubTree ID="Sub"/><Sleep msec="0"/></Sequence>',
            ),
            tree_def("Sub", '<Fallback><AlwaysFailure/><AlwaysSuccess name="ok"/></Fallback>'),
        )
    )
    paths = {node.uid: node.full_path for node in tree.nodes()}
    # uids are depth-first; a subtree's nodes are numbered when its <SubTree> is reached
    assert paths == {
        1: "root_seq",
        2: "Script::2",
        3: "sub1",
        4: "sub1/Fallback::4",
        5: "sub1/AlwaysFailure::5",
        6: "sub1/ok",
        7: "Sub::7",
        8: "Sub::7/Fallback::8",
        9: "Sub::7/AlwaysFailure::9",
        10: "Sub::7/ok",
        11: "Sleep::11",
    }
    assert [s.instance_name for s in tree.subtrees] == ["", "sub1", "Sub::7"]
    assert tree.node_by_path("sub1/ok").uid == 6


def test_recursive_subtree_is_reported(bench) -> None:
    with pytest.raises(BTError, match="Recursive behavior tree cycle"):
        bench.xml(
            doc(
                tree_def("Main", '<Sequence><SubTree ID="A"/></Sequence>'),
                tree_def("A", '<SubTree ID="Main"/>'),
            )
        )


def test_duplicate_subtree_paths_are_rejected(bench) -> None:
    with pytest.raises(BTError, match="Duplicate SubTree path detected: 'task'"):
        bench.xml(
            doc(
                tree_def(
                    "Main", '<Sequence><SubTree ID="T" name="task"/><SubTree ID="T" name="task"/></Sequence>'
                ),
                tree_def("T", "<AlwaysSuccess/>"),
            )
        )


def test_skip_if_on_a_subtree_applies_to_the_call(bench) -> None:
    bench.action("Inside")
    tree = bench.xml(
        doc(
            tree_def("Main", '<Sequence><SubTree ID="T" _skipIf="true"/><AlwaysSuccess/></Sequence>'),
            tree_def("T", "<Inside/>"),
        )
    )
    assert tree.tick_once() is S
    assert bench.ticks["Inside"] == 0
