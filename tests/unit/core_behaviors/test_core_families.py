"""The core plugin's layout: families exporting BEHAVIORS, each behavior with MoveIt Pro's metadata."""

from __future__ import annotations

import importlib
import sys
from typing import Any

FAMILIES = (
    "controllers",
    "files",
    "flow",
    "io",
    "messages",
    "motion",
    "mpc",
    "perception",
    "planning_scene",
    "poses",
    "task_planning",
    "ui",
    "vectors",
    "waiting",
    "waypoints",
)


def _plugin(registry: Any) -> Any:
    package = registry["CreatePoseStamped"].cls.__module__.split(".")[0]
    return sys.modules[package]


def test_the_loader_registers_the_union_of_the_families(registry: Any) -> None:
    plugin = _plugin(registry)
    union = []
    for family in FAMILIES:
        module = importlib.import_module(f"{plugin.__name__}.{family}")
        assert isinstance(module.BEHAVIORS, tuple) and module.BEHAVIORS, family
        union.extend(module.BEHAVIORS)
    assert len(union) == len(set(union)), "a behavior is exported by two families"
    core = {
        record.behavior_id for record in registry.values() if record.plugin == "kinema::CoreBehaviorsLoader"
    }
    assert {cls.__name__ for cls in union} == core


def test_every_core_behavior_has_a_description_and_a_subcategory(registry: Any) -> None:
    bare = [
        record.behavior_id
        for record in registry.values()
        if not record.metadata.get("description")
        or record.metadata.get("subcategory", "User Created Behaviors") == "User Created Behaviors"
    ]
    assert not bare, f"behaviors without a description or subcategory: {bare}"


def test_a_plugins_own_message_port_connects_to_the_core_behaviors(registry: Any) -> None:
    """Message port types come from the SDK, so another plugin's PoseStamped port is the core's type."""
    from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port, message_type
    from kinema.plugins import BehaviorRegistry
    from kinema.testing import registry_of, run_objective

    class NeedsPose(SyncBehavior):
        """Succeeds on a pose above the table."""

        subcategory = "Test"

        @classmethod
        def provided_ports(cls) -> list[PortInfo]:
            return [input_port("pose", message_type("geometry_msgs/msg/PoseStamped"), "{pose}")]

        def tick(self) -> NodeStatus:
            return NodeStatus.SUCCESS if self.get_input("pose").pose.position.z > 0.5 else NodeStatus.FAILURE

    combined = BehaviorRegistry({**registry, **registry_of([NeedsPose])})
    xml = """<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M"><Sequence>
      <Action ID="CreatePoseStamped" position_xyz="0;0;1" pose_stamped="{pose}"/>
      <Action ID="NeedsPose" pose="{pose}"/>
    </Sequence></BehaviorTree></root>"""
    assert run_objective(xml, registry=combined).status == NodeStatus.SUCCESS
