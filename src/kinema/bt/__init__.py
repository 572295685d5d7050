"""``kinema.bt``: a BehaviorTree.CPP v4.10-compatible behavior-tree engine in pure Python.

It loads BT.CPP v4 XML, registers every built-in node BT.CPP registers, lets Python code register
node types with typed ports, and ticks trees with BT.CPP's exact semantics (statuses, halting,
wake-up yields, SubTree remapping, the scripting language, pre/post-conditions). It imports nothing
from Kinema's robotics parts.
"""

from __future__ import annotations

from kinema.bt.blackboard import Blackboard, Entry
from kinema.bt.clock import Clock, ManualClock, WallClock
from kinema.bt.conversions import AnyValue
from kinema.bt.errors import (
    BTError,
    BTLogicError,
    BTRuntimeError,
    NodeExecutionError,
    ScriptError,
    ScriptParseError,
)
from kinema.bt.factory import BehaviorTreeFactory
from kinema.bt.manifest import NodeManifest, NodeType
from kinema.bt.model_xml import write_objective_xml, write_tree_nodes_model_xml, write_tree_to_xml
from kinema.bt.node import (
    ActionNode,
    ConditionNode,
    ControlNode,
    DecoratorNode,
    NodeConfig,
    PortError,
    PortResult,
    StatefulActionNode,
    SyncActionNode,
    TreeNode,
)
from kinema.bt.observer import NodeStatistics, TreeObserver
from kinema.bt.ports import PortDirection, PortInfo, bidirectional_port, input_port, output_port
from kinema.bt.spellings import FormerSpelling
from kinema.bt.status import NodeStatus
from kinema.bt.tree import Subtree, Tree

__all__ = [
    "ActionNode",
    "AnyValue",
    "BTError",
    "BTLogicError",
    "BTRuntimeError",
    "BehaviorTreeFactory",
    "Blackboard",
    "Clock",
    "ConditionNode",
    "ControlNode",
    "DecoratorNode",
    "Entry",
    "FormerSpelling",
    "ManualClock",
    "NodeConfig",
    "NodeExecutionError",
    "NodeManifest",
    "NodeStatistics",
    "NodeStatus",
    "NodeType",
    "PortDirection",
    "PortError",
    "PortInfo",
    "PortResult",
    "ScriptError",
    "ScriptParseError",
    "StatefulActionNode",
    "Subtree",
    "SyncActionNode",
    "Tree",
    "TreeNode",
    "TreeObserver",
    "WallClock",
    "bidirectional_port",
    "input_port",
    "output_port",
    "write_objective_xml",
    "write_tree_nodes_model_xml",
    "write_tree_to_xml",
]
