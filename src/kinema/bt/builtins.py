"""Registration of every node ID BT.CPP 4.10 registers by default (reference §2.1): 42 IDs."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from kinema.bt import actions, controls, decorators

if TYPE_CHECKING:
    from kinema.bt.factory import BehaviorTreeFactory

BUILTIN_NODE_TYPES: dict[str, type] = {
    # controls
    "Fallback": controls.FallbackNode,
    "AsyncFallback": controls.AsyncFallbackNode,
    "Sequence": controls.SequenceNode,
    "AsyncSequence": controls.AsyncSequenceNode,
    "SequenceWithMemory": controls.SequenceWithMemoryNode,
    "Parallel": controls.ParallelNode,
    "ParallelAll": controls.ParallelAllNode,
    "ReactiveSequence": controls.ReactiveSequenceNode,
    "ReactiveFallback": controls.ReactiveFallbackNode,
    "IfThenElse": controls.IfThenElseNode,
    "WhileDoElse": controls.WhileDoElseNode,
    "TryCatch": controls.TryCatchNode,
    **{f"Switch{n}": controls.make_switch(n) for n in range(2, 7)},
    # decorators
    "Inverter": decorators.InverterNode,
    "RetryUntilSuccessful": decorators.RetryNode,
    "KeepRunningUntilFailure": decorators.KeepRunningUntilFailureNode,
    "Repeat": decorators.RepeatNode,
    "Timeout": decorators.TimeoutNode,
    "Delay": decorators.DelayNode,
    "RunOnce": decorators.RunOnceNode,
    "ForceSuccess": decorators.ForceSuccessNode,
    "ForceFailure": decorators.ForceFailureNode,
    "Precondition": decorators.PreconditionNode,
    "LoopInt": decorators.make_loop("LoopInt", int),
    "LoopBool": decorators.make_loop("LoopBool", bool),
    "LoopDouble": decorators.make_loop("LoopDouble", float),
    "LoopString": decorators.make_loop("LoopString", str),
    "SkipUnlessUpdated": decorators.SkipUnlessUpdatedNode,
    "WaitValueUpdate": decorators.WaitValueUpdateNode,
    "SubTree": decorators.SubTreeNode,
    # actions
    "AlwaysSuccess": actions.AlwaysSuccessNode,
    "AlwaysFailure": actions.AlwaysFailureNode,
    "Script": actions.ScriptNode,
    "SetBlackboard": actions.SetBlackboardNode,
    "Sleep": actions.SleepNode,
    "UnsetBlackboard": actions.UnsetBlackboardNode,
    "WasEntryUpdated": actions.WasEntryUpdatedNode,
    # conditions
    "ScriptCondition": actions.ScriptConditionNode,
}


# What registering the built-ins computes from the classes (ports, description, metadata), once per
# process: (ID, class, category, ports, description, metadata).
_BUILTIN_MANIFEST_ARGS: list[tuple[str, type, Any, dict, str, list]] = []


def register_builtin_nodes(factory: BehaviorTreeFactory) -> None:
    """Register the built-in node types on ``factory``.

    The first factory of a process registers each class (reading its ports and description); later
    ones get new manifests from what that found, about ten times quicker (a new factory per build
    is what one-off tools and tests do).
    """
    from kinema.bt.manifest import NodeManifest, NodeType

    if not _BUILTIN_MANIFEST_ARGS or factory._builders:
        for node_id, cls in BUILTIN_NODE_TYPES.items():
            factory.register_node_type(cls, node_id, builtin=True)
        factory._manifests["SubTree"].category = NodeType.SUBTREE
        if not _BUILTIN_MANIFEST_ARGS:
            for node_id, cls in BUILTIN_NODE_TYPES.items():
                m = factory._manifests[node_id]
                args = (node_id, cls, m.category, dict(m.ports), m.description, list(m.metadata))
                _BUILTIN_MANIFEST_ARGS.append(args)
        return
    builders = factory._builders
    manifests = factory._manifests
    for node_id, cls, category, ports, description, metadata in _BUILTIN_MANIFEST_ARGS:
        builders[node_id] = cls
        # Each factory owns its manifests (NodeManifest copies the ports dict and metadata list).
        manifests[node_id] = NodeManifest(node_id, category, ports, description, metadata, True)
    factory._generation += 1
