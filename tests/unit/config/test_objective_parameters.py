"""An objective's parameters: one rule for `kinema objective show`, the SDK's list and the UI's form."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from kinema.bt import BehaviorTreeFactory, NodeStatus, SyncActionNode
from kinema.bt.ports import input_port, output_port
from kinema.config.objective_file import parse_objective_file
from kinema.config.objective_parameters import objective_interface, objective_parameters
from kinema.runtime.overrides import ParameterOverride, apply_overrides

# The tutorial's objective: no declared ports, yet `-p a=40 -p b=2` sets what MyBehavior reads.
ADD_NUMBERS = """<root BTCPP_format="4" main_tree_to_execute="Add Numbers">
  <BehaviorTree ID="Add Numbers" _description="Add a and b with MyBehavior; the sum is in {sum}.">
    <Control ID="Sequence">
      <Action ID="MyBehavior" int_1="{a}" int_2="{b}" int_out="{sum}"/>
      <Action ID="MyBehavior" name="twice" int_1="{sum}" int_2="{b}" int_out="{twice}"/>
    </Control>
  </BehaviorTree>
  <TreeNodesModel>
    <SubTree ID="Add Numbers">
      <MetadataFields><Metadata runnable="true"/></MetadataFields>
    </SubTree>
  </TreeNodesModel>
</root>"""

# Declared ports (with defaults) come first; one is passed to a subtree whose behavior says its type.
WITH_DECLARED = """<root BTCPP_format="4">
  <BehaviorTree ID="Scaled Add">
    <Sequence>
      <SubTree ID="Add Numbers" a="{offset}" b="{scale}"/>
      <Action ID="MyBehavior" int_1="{unused_default}" int_2="{extra}" int_out="{result}"/>
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <SubTree ID="Scaled Add">
      <input_port name="scale" default="2">How much to add</input_port>
      <output_port name="result"/>
    </SubTree>
  </TreeNodesModel>
</root>"""


class MyBehavior(SyncActionNode):
    """The tutorial's behavior: int_out = int_1 + int_2."""

    @classmethod
    def provided_ports(cls):
        return [input_port("int_1", int), input_port("int_2", int), output_port("int_out", int)]

    def tick(self) -> NodeStatus:
        self.set_output("int_out", self.get_input("int_1") + self.get_input("int_2"))
        return NodeStatus.SUCCESS


@pytest.fixture
def library(tmp_path: Path):
    (tmp_path / "add_numbers.xml").write_text(ADD_NUMBERS)
    (tmp_path / "scaled_add.xml").write_text(WITH_DECLARED)
    factory = BehaviorTreeFactory()
    factory.register_node_type(MyBehavior)
    infos = {}
    for path in sorted(tmp_path.glob("*.xml")):
        factory.register_behavior_tree_from_file(path)
        for info in parse_objective_file(path).objectives:
            infos[info.id] = info
    return factory, infos


def _table(ports) -> list[tuple[str, str, str, str | None]]:
    return [(p.name, p.direction, p.type_name, p.default) for p in ports]


def test_add_numbers_has_the_parameters_its_behavior_reads(library) -> None:
    factory, infos = library
    parameters = objective_parameters(infos["Add Numbers"], factory)
    # {sum} is written before "twice" reads it, so it is no parameter; {b} is listed once.
    assert _table(parameters) == [("a", "input", "int", None), ("b", "input", "int", None)]
    assert parameters[0].description == "read by MyBehavior.int_1"
    # Exactly those names are what the runtime accepts as overrides, parsed into the port's type.
    tree = factory.create_tree("Add Numbers")
    apply_overrides(tree, [ParameterOverride("a", "40"), ParameterOverride("b", "2")])
    assert tree.tick_while_running(0.0) is NodeStatus.SUCCESS
    assert tree.root_blackboard.get("sum") == 42


def test_declared_ports_first_then_keys_read_with_types_through_subtrees(library) -> None:
    factory, infos = library
    info = infos["Scaled Add"]
    assert _table(objective_parameters(info, factory)) == [
        ("scale", "input", "int", "2"),
        ("offset", "input", "int", None),
        ("unused_default", "input", "int", None),
        ("extra", "input", "int", None),
    ]
    assert _table(objective_interface(info, factory))[-1] == ("result", "output", "", None)


def test_without_behaviors_only_the_declared_ports_are_known(library) -> None:
    _, infos = library
    assert _table(objective_parameters(infos["Scaled Add"])) == [("scale", "input", "", "2")]
    assert objective_parameters(infos["Add Numbers"]) == []


def test_objective_show_lists_typed_parameters(capsys) -> None:
    from kinema.cli.main import main

    code = main(["objective", "show", "Move to Waypoint", "-c", "lab_sim", "--json"])
    shown = json.loads(capsys.readouterr().out)
    assert code == 0
    ports = {p["name"]: p for p in shown["ports"]}
    assert ports["link_padding"] == {
        "name": "link_padding",
        "direction": "input",
        "type": "double",
        "default": "0.01",
        "description": "Clearance (m) kept between the robot and the scene.",
    }
    assert ports["waypoint_name"]["type"] == "std::string"
    code = main(["objective", "show", "Move to Waypoint", "-c", "lab_sim"])
    out = capsys.readouterr().out
    assert code == 0
    assert "input  link_padding" in out and "double" in out and "ports:       none" not in out
    # Its default is "", which sets nothing: said as such, with how to give it.
    assert "= (none; -p waypoint_name=VALUE sets it)" in out
