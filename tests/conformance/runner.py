"""Conformance runner: executes a BT.CPP conformance corpus (YAML) with kinema.bt.

Usage: ``python tests/conformance/runner.py CORPUS.yaml`` prints one JSON line per case and per script
case, as the runner contract in ``../shared/conformance/README.md`` describes. ``check.py`` compares
the observations with what BehaviorTree.CPP 4.10 does.
"""

from __future__ import annotations

import json
import sys
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

import yaml

from kinema.bt import (
    BehaviorTreeFactory,
    Blackboard,
    BTError,
    BTLogicError,
    BTRuntimeError,
    ConditionNode,
    NodeStatus,
    StatefulActionNode,
    SyncActionNode,
    TreeNode,
    TreeObserver,
    input_port,
    output_port,
)
from kinema.bt.conversions import cast_value
from kinema.bt.script import parse_script

_TYPES: dict[str, Any] = {"int": int, "double": float, "string": str, "bool": bool}


class Observation:
    """Counters and logs the mock nodes of one case write to."""

    def __init__(self) -> None:
        self.counters: dict[str, int] = defaultdict(int)
        self.logs: dict[str, list[str]] = defaultdict(list)


def error_type(error: BaseException) -> str:
    """BT.CPP's exception type name for an error raised by the engine."""
    if isinstance(error, BTLogicError):
        return "LogicError"
    if isinstance(error, BTRuntimeError):
        return "RuntimeError"
    if isinstance(error, BTError):
        return "BehaviorTreeException"
    return type(error).__name__


def _status(name: str) -> NodeStatus:
    return NodeStatus[name]


def _register_counter(
    factory: BehaviorTreeFactory, node_id: str, spec: dict, obs: Observation, condition: bool
) -> None:
    returns = [_status(s) for s in spec.get("returns", ["SUCCESS"])]

    def tick(node: TreeNode) -> NodeStatus:
        obs.counters[node_id] += 1
        k = obs.counters[node_id]
        return returns[min(k, len(returns)) - 1]

    if condition:
        factory.register_simple_condition(node_id, tick)
    else:
        factory.register_simple_action(node_id, tick)


def _register_stateful(factory: BehaviorTreeFactory, node_id: str, spec: dict, obs: Observation) -> None:
    running_ticks = int(spec.get("running_ticks", 0))
    result = _status(spec.get("result", "SUCCESS"))

    class Stateful(StatefulActionNode):
        def on_start(self) -> NodeStatus:
            obs.counters[node_id] += 1
            obs.counters[node_id + ".starts"] += 1
            self.n = 0
            return result if running_ticks == 0 else NodeStatus.RUNNING

        def on_running(self) -> NodeStatus:
            obs.counters[node_id] += 1
            self.n += 1
            if running_ticks >= 0 and self.n >= running_ticks:
                return result
            return NodeStatus.RUNNING

        def on_halted(self) -> None:
            obs.counters[node_id + ".halts"] += 1

    factory.register_node_type(Stateful, node_id)


def _register_bb_condition(factory: BehaviorTreeFactory, node_id: str, spec: dict, obs: Observation) -> None:
    key = spec["key"]

    class BBCondition(ConditionNode):
        def tick(self) -> NodeStatus:
            obs.counters[node_id] += 1
            return NodeStatus.SUCCESS if self.config.blackboard.get(key, bool) else NodeStatus.FAILURE

    factory.register_node_type(BBCondition, node_id)


def _register_bb_setter_async(
    factory: BehaviorTreeFactory, node_id: str, spec: dict, obs: Observation
) -> None:
    key = spec["key"]
    after = int(spec.get("after", 1))

    class Setter(StatefulActionNode):
        def on_start(self) -> NodeStatus:
            obs.counters[node_id] += 1
            self.calls = 0
            return NodeStatus.RUNNING

        def on_running(self) -> NodeStatus:
            obs.counters[node_id] += 1
            self.calls += 1
            if self.calls >= after:
                self.config.blackboard.set(key, True)
                return NodeStatus.SUCCESS
            return NodeStatus.RUNNING

    factory.register_node_type(Setter, node_id)


def _register_message(
    factory: BehaviorTreeFactory, node_id: str, obs: Observation, raise_if_missing: bool
) -> None:
    class Message(SyncActionNode):
        @classmethod
        def provided_ports(cls) -> list:
            return [input_port("message", str)]

        def tick(self) -> NodeStatus:
            result = self.try_get_input("message")
            if not result.ok:
                if raise_if_missing:
                    raise BTRuntimeError(f"Missing required input [message]: {result.error}")
                return NodeStatus.FAILURE
            obs.logs[node_id].append(result.value)
            return NodeStatus.SUCCESS

    factory.register_node_type(Message, node_id)


def _register_bb_test_node(factory: BehaviorTreeFactory, node_id: str) -> None:
    class BBTest(SyncActionNode):
        @classmethod
        def provided_ports(cls) -> list:
            return [input_port("in_port", int), output_port("out_port", int)]

        def tick(self) -> NodeStatus:
            value = self.get_input("in_port")
            self.set_output("out_port", value * 2)
            return NodeStatus.SUCCESS

    factory.register_node_type(BBTest, node_id)


def _register_node_with_ports(factory: BehaviorTreeFactory, node_id: str) -> None:
    class WithPorts(SyncActionNode):
        @classmethod
        def provided_ports(cls) -> list:
            return [input_port("in_port_A", int, 42), input_port("in_port_B", int)]

        def tick(self) -> NodeStatus:
            a = self.get_input("in_port_A")
            b = self.get_input("in_port_B")
            return NodeStatus.SUCCESS if a == 42 and b == 66 else NodeStatus.FAILURE

    factory.register_node_type(WithPorts, node_id)


def _register_typed_ports(factory: BehaviorTreeFactory, node_id: str, port_type: type, double: bool) -> None:
    class Typed(SyncActionNode):
        @classmethod
        def provided_ports(cls) -> list:
            return [input_port("input", port_type), output_port("output", port_type)]

        def tick(self) -> NodeStatus:
            result = self.try_get_input("input")
            if not result.ok:
                return NodeStatus.FAILURE
            self.set_output("output", result.value * 2 if double else result.value)
            return NodeStatus.SUCCESS

    factory.register_node_type(Typed, node_id)


def register_mocks(factory: BehaviorTreeFactory, nodes: dict, obs: Observation) -> str | None:
    """Register the case's mock nodes; return an 'unsupported' reason or None."""
    for node_id, spec in (nodes or {}).items():
        kind = spec.get("kind")
        if kind in ("counter_action", "counter_condition"):
            _register_counter(factory, node_id, spec, obs, kind == "counter_condition")
        elif kind == "stateful":
            _register_stateful(factory, node_id, spec, obs)
        elif kind == "bb_condition":
            _register_bb_condition(factory, node_id, spec, obs)
        elif kind == "bb_setter_async":
            _register_bb_setter_async(factory, node_id, spec, obs)
        elif kind in ("say_something", "print_to_console"):
            _register_message(factory, node_id, obs, kind == "say_something")
        elif kind == "bb_test_node":
            _register_bb_test_node(factory, node_id)
        elif kind == "node_with_ports":
            _register_node_with_ports(factory, node_id)
        elif kind == "int_ports":
            _register_typed_ports(factory, node_id, int, True)
        elif kind == "string_ports":
            _register_typed_ports(factory, node_id, str, False)
        elif kind == "double_ports":
            _register_typed_ports(factory, node_id, float, False)
        else:
            return f"unknown mock kind {kind!r}"
    return None


def _set_values(bb: Blackboard, values: dict) -> None:
    for key, spec in values.items():
        bb.set(key, _TYPES[spec["type"]](spec["value"]))


def read_back(bb: Blackboard, key: str) -> dict:
    """The value of ``key`` read as each type (or an error per type)."""
    out: dict[str, Any] = {}
    for name, target in _TYPES.items():
        try:
            out[name] = bb.get(key, target)
        except BTError as error:
            out[name] = {"error": error.message}
    return out


def run_case(case: dict) -> dict:
    """Build and run one tree case; return its observation."""
    obs = Observation()
    factory = BehaviorTreeFactory()
    unsupported = register_mocks(factory, case.get("nodes") or {}, obs)
    if unsupported:
        return {"unsupported": unsupported}
    bb = Blackboard.create()
    _set_values(bb, case.get("blackboard") or {})
    try:
        if case.get("main_tree"):
            factory.register_behavior_tree_from_text(case["xml"])
            tree = factory.create_tree(case["main_tree"], bb)
        else:
            tree = factory.create_tree_from_text(case["xml"], bb)
    except Exception as error:
        return {"create_error": {"type": error_type(error), "message": getattr(error, "message", str(error))}}
    observer = TreeObserver(tree)
    steps = []
    for step in case.get("steps") or []:
        row: dict[str, Any] = {}
        start = time.monotonic()
        try:
            if "tick" in step:
                mode = step["tick"]
                if mode == "once":
                    status = tree.tick_once()
                elif mode == "exactly_once":
                    status = tree.tick_exactly_once()
                else:
                    status = tree.tick_while_running(0.01)
                row["status"] = status.name
            elif "set" in step:
                _set_values(tree.root_blackboard, step["set"])
            elif "halt" in step:
                tree.halt_tree()
            elif "sleep_ms" in step:
                time.sleep(step["sleep_ms"] / 1000.0)
        except Exception as error:
            row["error"] = {"type": error_type(error), "message": getattr(error, "message", str(error))}
        row["elapsed_ms"] = (time.monotonic() - start) * 1000.0
        row["counters"] = dict(obs.counters)
        row["logs"] = {k: list(v) for k, v in obs.logs.items()}
        row["bb"] = {key: read_back(tree.root_blackboard, key) for key in (step.get("bb") or {})}
        row["observer"] = {}
        for path in step.get("observer") or {}:
            try:
                stats = observer.statistics(path)
            except BTError:
                continue
            row["observer"][path] = {
                "success_count": stats.success_count,
                "failure_count": stats.failure_count,
                "transitions_count": stats.transitions_count,
            }
        steps.append(row)
    tree.halt_tree()
    return {"steps": steps}


def run_script(case: dict) -> dict:
    """Parse and run one script case on an empty blackboard."""
    try:
        script = parse_script(case["code"])
    except BTError as error:
        return {"parse_ok": False, "parse_error": error.message}
    out: dict[str, Any] = {"parse_ok": True}
    try:
        value = script.run(Blackboard.create(), {})
    except BTError as error:
        out["eval_error"] = error.message
        return out
    for name, target in _TYPES.items():
        if value is None:
            continue
        try:
            out[name] = cast_value(value, target)
        except BTError:
            continue
    return out


def main(argv: list[str]) -> int:
    """Run every case of the corpus given as the last argument."""
    if not argv:
        print(__doc__)
        return 2
    corpus = yaml.safe_load(Path(argv[-1]).read_text())
    for case in corpus.get("cases") or []:
        try:
            observation = run_case(case)
        except Exception as error:  # the runner reports, the checker judges
            observation = {"unsupported": f"runner crashed: {type(error).__name__}: {error}"}
        print(json.dumps({"case": case["name"], "observation": observation}, default=str), flush=True)
    for index, case in enumerate(corpus.get("script_cases") or []):
        try:
            observation = run_script(case)
        except Exception as error:
            observation = {"parse_ok": True, "eval_error": f"runner crashed: {type(error).__name__}: {error}"}
        print(json.dumps({"script": index, "observation": observation}, default=str), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
