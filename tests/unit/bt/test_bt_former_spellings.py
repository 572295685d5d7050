"""Former spellings in the engine: an old node ID or port name is read as today's, with a note."""

from __future__ import annotations

from pathlib import Path

import pytest

from kinema.bt import BehaviorTreeFactory, BTError, FormerSpelling, NodeStatus, input_port
from kinema.bt.validation import Problem, validate_files


def _factory(*, old_registered: bool = False) -> tuple[BehaviorTreeFactory, list[object]]:
    seen: list[object] = []
    factory = BehaviorTreeFactory()
    factory.register_simple_action(
        "Current", lambda node: seen.append(node.get_input("a")) or NodeStatus.SUCCESS, [input_port("a", int)]
    )
    if old_registered:
        factory.register_simple_action("Old", lambda node: NodeStatus.FAILURE, [input_port("x", int)])
    factory.register_former_spelling(FormerSpelling("Old", ports={"x": "a"}, current_id="Current"))
    return factory, seen


def _xml(node: str) -> str:
    head = '<root BTCPP_format="4" main_tree_to_execute="T">\n<BehaviorTree ID="T">\n'
    return f"{head}{node}\n</BehaviorTree>\n</root>"


@pytest.mark.parametrize("node", ['<Old x="7"/>', '<Action ID="Old" x="7"/>'])
def test_an_old_id_and_port_run_as_the_current_node(node: str) -> None:
    factory, seen = _factory()
    tree = factory.create_tree_from_text(_xml(node), filename="old.xml")
    assert tree.tick_once() is NodeStatus.SUCCESS
    assert seen == [7]
    (note,) = factory.library.spelling_notes
    assert str(note) == (
        "old.xml:3: Old is MoveIt Pro's old name of Current (its port x is a); "
        "read as Current, write that instead"
    )


def test_a_node_type_registered_under_the_old_id_wins_over_the_rename() -> None:
    factory, seen = _factory(old_registered=True)
    tree = factory.create_tree_from_text(_xml('<Old x="7"/>'), filename="old.xml")
    assert tree.tick_once() is NodeStatus.FAILURE
    assert seen == [] and not factory.library.spelling_notes


def test_old_and_current_port_together_are_refused_not_guessed() -> None:
    factory, _ = _factory()
    with pytest.raises(BTError, match=r"port with name \[x\]"):
        factory.create_tree_from_text(_xml('<Old x="7" a="8"/>'), filename="old.xml")


def test_an_old_id_cannot_be_the_old_name_of_two_node_types() -> None:
    factory, _ = _factory()
    factory.register_simple_action("Other", lambda node: NodeStatus.SUCCESS)
    with pytest.raises(BTError, match="old name of both Current and Other"):
        factory.register_former_spelling(FormerSpelling("Old", current_id="Other"))


def test_validation_reports_each_old_spelling_as_a_warning_not_a_problem(tmp_path: Path) -> None:
    factory, _ = _factory()
    path = tmp_path / "old.xml"
    path.write_text(_xml('<Sequence>\n<Old x="1"/>\n<Current x="2"/>\n</Sequence>'))
    warnings: list[Problem] = []
    problems = validate_files([path], factory, warnings=warnings)
    # Only the old ID is renamed: an old port under today's ID is today's unknown port.
    assert [str(problem) for problem in problems] == [
        f"{path}:5: port [x] is not a port of Current; valid: a"
    ]
    assert [str(warning) for warning in warnings] == [
        f"{path}:4: Old is MoveIt Pro's old name of Current (its port x is a); "
        "read as Current, write that instead"
    ]


def test_an_old_id_also_gets_the_current_ids_old_port_names() -> None:
    factory, seen = _factory()
    factory.register_former_spelling(FormerSpelling(ports={"b": "a"}, current_id="Current"))
    factory.register_former_spelling(FormerSpelling("Older", current_id="Current"))
    tree = factory.create_tree_from_text(_xml('<Older b="5"/>'), filename="old.xml")
    assert tree.tick_once() is NodeStatus.SUCCESS
    assert seen == [5]
    assert [note.message.split(";")[0] for note in factory.library.spelling_notes] == [
        "Older is MoveIt Pro's old name of Current",
        "Current's port b is MoveIt Pro's old name of a",
    ]
