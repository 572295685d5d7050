"""Seeded random BT.CPP v4 documents for the differential test against behaviortreepy (BT.CPP 4.8.2).

A document is a main tree plus SubTrees built from the built-in controls and decorators, Script,
ScriptCondition, SetBlackboard, pre/post-condition attributes and the scripted leaves of
``btcpp_oracle`` (``Act``, ``Cond``, ``Async``). Every node gets a unique instance name (``n<k>``)
so transitions printed by BT.CPP's StdCoutLogger can be matched to nodes; each SubTree ID is used
by one SubTree node only, for the same reason.

Kinema follows BT.CPP 4.10; the oracle is 4.8.2. These are the 4.8 -> 4.10 changes where Kinema
follows 4.10 (shared/reference/btcpp-v4-semantics.md section 0 and BT.CPP's CHANGELOG for 4.8.3 to
4.10.0), and how the generator keeps the trees it makes out of them, so both versions agree:

* 4.9.0 #1029 ``A - B + C`` chains are left-associative (right-associative in 4.8)
  -> binary operators only take atoms or parenthesised operands, one operator per level;
* 4.9.0 #1099 hand-written Pratt parser replaces lexy: ``&&`` binds tighter than ``||``; math,
  bitwise and ``..`` mix without parentheses; prefix operators apply to any operand
  -> ``&&``/``||`` never mixed unparenthesised, no such mixes, prefix only on parenthesised operands;
* 4.9.0 #1099 ``true``/``false`` are doubles 1.0/0.0 (int64 1/0 in 4.8)
  -> used only in conditions, never stored;
* 4.9.0 #1099 double-quoted script strings are rejected -> single quotes only;
* 4.9.0 #1099 an integer literal beyond int64 reads as 0 (a parse error at createTree in 4.8)
  -> no such literal (test_bt_script covers 4.10's rule);
* 4.9.0 TryCatch control node -> not generated;
* 4.9.0 #1106 exceptions from tick() wrapped in NodeExecutionError (the original in 4.8)
  -> only "an exception escaped this tick" is compared, not its type or text;
* 4.9.1 #1121 literal SubTree attributes keep numeric types (always strings in 4.8)
  -> SubTrees remap only ``{key}`` pointers or use ``_autoremap``;
* 4.9.0 #1085 recursive SubTree cycles detected, 4.8.4 duplicate SubTree paths rejected,
  4.8.4 new name validation rules -> SubTree IDs unique and never recursive, names ``n<k>``;
* 4.9.0 #969 LoopX queue port untyped, #1112 EntryUpdated halts its child -> not generated;
* 4.9.0 #1097/#1103 Delay created from XML honours delay_msec -> time-based nodes (Delay,
  Timeout, Sleep) are left out anyway: the comparison is tick by tick;
* 4.10.0 #1178 Switch numeric cases reject trailing characters
  -> Switch variables and cases are strings without a numeric prefix, or plain integers;
* 4.10.0 #1162 float-to-int cast at the int64 limit -> no such values.

Two more things the generator avoids, where 4.8.2 misbehaves: SetBlackboard on an entry
seeded from C++ as ``std::string`` throws "convertFromString ... BT::Any" in 4.8.2, so
SetBlackboard writes only a key of its own (``f``); BT.CPP's Tree destructor halts the tree and an
``_onHalted`` script that throws there terminates the process, so those scripts cannot fail.

Loops are bounded (Repeat/Retry counts 1-3, never -1) so a tick always ends.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field
from xml.sax.saxutils import quoteattr

from btcpp_oracle import Leaves

#: The variables scripts use; the seed blackboard holds a, b (int) and s (string).
SEED_BLACKBOARD = {"a": 0, "b": 2, "s": "x"}

_ASSIGN = [
    "a := a + 1",
    "a = (a * 2)",
    "b := b - 1",
    "a += 1",
    "b -= 2",
    "c := 5",
    "c := (a + 1)",
    "c += 1",  # fails while c does not exist
    "d := 2.5",
    "d := (d * 2)",  # fails while d does not exist
    "s := s .. 'y'",
    "s = 'x'",
    "t := s .. a",
    "e := (a > 1) ? 10 : 20",
    "a := 1; b := 3",
    "u = 1",  # always fails: '=' on a missing entry
    "b := (b / 2)",  # fails once b is odd: int entry, fractional result
]

_SAFE_ASSIGN = ["h := 1", "g := 'halted'"]

_RARE_CONDITION = [
    "c > 5",  # fails while c does not exist
    "e == 10",  # fails while e does not exist
]

_CONDITION = [
    "a > 1",
    "a < 3",
    "b == 2",
    "b != 0",
    "s == 'x'",
    "(a > 0) && (b > 0)",
    "(a == 0) || (b == 3)",
    "!(a > 2)",
    "a >= b",
]

_STATUS = ["SUCCESS", "FAILURE"]


@dataclass
class Generated:
    """One random document and what the leaves do."""

    xml: str
    leaves: Leaves
    ticks: int
    halt_before: int | None
    seed_bb: dict = field(default_factory=lambda: dict(SEED_BLACKBOARD))


class _Builder:
    def __init__(self, rng: random.Random, max_depth: int) -> None:
        self.rng = rng
        self.max_depth = max_depth
        self.counter = 0
        self.leaves = Leaves()
        self.subtrees: list[str] = []

    def name(self) -> str:
        self.counter += 1
        return f"n{self.counter}"

    def condition(self) -> str:
        return self.rng.choice(_RARE_CONDITION if self.rng.random() < 0.15 else _CONDITION)

    def attrs(self, pairs: dict[str, str]) -> str:
        return "".join(f" {k}={quoteattr(v)}" for k, v in pairs.items())

    def conditions(self) -> dict[str, str]:
        rng = self.rng
        out: dict[str, str] = {}
        if rng.random() < 0.12:
            attr = rng.choice(["_skipIf", "_successIf", "_failureIf", "_while"])
            out[attr] = self.condition()
        if rng.random() < 0.1:
            attr = rng.choice(["_onSuccess", "_onFailure", "_post", "_onHalted"])
            # BT.CPP's Tree destructor halts the tree: an _onHalted script that throws there
            # terminates the process, so those scripts cannot fail.
            out[attr] = rng.choice(_SAFE_ASSIGN if attr == "_onHalted" else _ASSIGN)
        return out

    def leaf(self) -> str:
        rng = self.rng
        name = self.name()
        kind = rng.choices(
            ["Act", "Cond", "Async", "Script", "ScriptCondition", "AlwaysSuccess", "AlwaysFailure", "Set"],
            weights=[3, 2, 4, 3, 2, 1, 1, 1],
        )[0]
        attrs: dict[str, str] = {"name": name}
        if kind in ("Act", "Cond"):
            self.leaves.scripts[name] = [rng.choice(_STATUS) for _ in range(rng.randint(1, 4))]
        elif kind == "Async":
            choices = ["RUNNING", "RUNNING", "SUCCESS", "FAILURE"]
            self.leaves.scripts[name] = [rng.choice(choices) for _ in range(rng.randint(2, 5))]
        elif kind == "Script":
            attrs["code"] = rng.choice(_ASSIGN)
        elif kind == "ScriptCondition":
            attrs["code"] = self.condition()
        elif kind == "Set":
            kind = "SetBlackboard"
            attrs["output_key"] = "f"
            attrs["value"] = rng.choice(["7", "hello", "x"])
        attrs.update(self.conditions())
        return f"<{kind}{self.attrs(attrs)}/>"

    def node(self, depth: int) -> str:
        rng = self.rng
        if depth >= self.max_depth or rng.random() < 0.2 + 0.15 * depth:
            return self.leaf()
        kind = rng.choices(["control", "decorator", "subtree"], weights=[5, 4, 1])[0]
        if kind == "subtree" and len(self.subtrees) < 3:
            return self.subtree(depth)
        if kind == "decorator":
            return self.decorator(depth)
        return self.control(depth)

    def children(self, depth: int, low: int, high: int) -> str:
        return "".join(self.node(depth + 1) for _ in range(self.rng.randint(low, high)))

    def control(self, depth: int) -> str:
        rng = self.rng
        kind = rng.choice(
            [
                "Sequence",
                "SequenceWithMemory",
                "Fallback",
                "ReactiveSequence",
                "ReactiveFallback",
                "Parallel",
                "ParallelAll",
                "IfThenElse",
                "WhileDoElse",
                "Switch2",
                "Switch3",
            ]
        )
        attrs: dict[str, str] = {"name": self.name()}
        if kind in ("IfThenElse", "WhileDoElse"):
            body = self.children(depth, 2, 3)
        elif kind.startswith("Switch"):
            cases = int(kind[-1])
            # a and b are int entries: a Switch (a std::string port) on them is refused at creation
            attrs["variable"] = rng.choice(["{s}", "{f}", "{t}"])
            for i in range(1, cases + 1):
                attrs[f"case_{i}"] = rng.choice(["7", "x", "xy", "hello", "x0"])
            body = "".join(self.node(depth + 1) for _ in range(cases + 1))
        else:
            count = rng.randint(1, 4)
            body = "".join(self.node(depth + 1) for _ in range(count))
            if kind == "Parallel":
                attrs["success_count"] = str(rng.choice([-1, 1, 2, count]))
                attrs["failure_count"] = str(rng.choice([-1, 1, 2, count]))
            elif kind == "ParallelAll":
                attrs["max_failures"] = str(rng.choice([0, 1, 2, -1]))
        attrs.update(self.conditions())
        return f"<{kind}{self.attrs(attrs)}>{body}</{kind}>"

    def decorator(self, depth: int) -> str:
        rng = self.rng
        kind = rng.choice(
            [
                "Inverter",
                "ForceSuccess",
                "ForceFailure",
                "Repeat",
                "RetryUntilSuccessful",
                "KeepRunningUntilFailure",
                "RunOnce",
                "Precondition",
            ]
        )
        attrs: dict[str, str] = {"name": self.name()}
        if kind == "Repeat":
            attrs["num_cycles"] = str(rng.randint(1, 3))
        elif kind == "RetryUntilSuccessful":
            attrs["num_attempts"] = str(rng.randint(1, 3))
        elif kind == "RunOnce":
            attrs["then_skip"] = rng.choice(["true", "false"])
        elif kind == "Precondition":
            attrs["if"] = self.condition()
            attrs["else"] = rng.choice(["FAILURE", "SUCCESS", "RUNNING", "SKIPPED"])
        attrs.update(self.conditions())
        return f"<{kind}{self.attrs(attrs)}>{self.node(depth + 1)}</{kind}>"

    def subtree(self, depth: int) -> str:
        rng = self.rng
        tree_id = f"Sub{len(self.subtrees) + 1}"
        self.subtrees.append("")  # reserve the slot before building (nested subtrees)
        slot = len(self.subtrees) - 1
        body = self.node(depth + 1)
        self.subtrees[slot] = f'<BehaviorTree ID="{tree_id}">{body}</BehaviorTree>'
        attrs: dict[str, str] = {"ID": tree_id, "name": self.name()}
        mode = rng.choice(["auto", "remap", "private"])
        if mode == "auto":
            attrs["_autoremap"] = "true"
        elif mode == "remap":
            for key in rng.sample(["a", "b", "s", "c"], rng.randint(1, 3)):
                attrs[key] = "{" + key + "}"
        return f"<SubTree{self.attrs(attrs)}/>"


def random_document(seed: int, max_depth: int = 4) -> Generated:
    """The document for ``seed`` (the same seed always gives the same document)."""
    rng = random.Random(seed)
    builder = _Builder(rng, max_depth)
    main = builder.control(0) if rng.random() < 0.85 else builder.node(0)
    trees = f'<BehaviorTree ID="Main">{main}</BehaviorTree>' + "".join(builder.subtrees)
    xml = f'<root BTCPP_format="4" main_tree_to_execute="Main">{trees}</root>'
    ticks = rng.randint(3, 8)
    halt_before = rng.randint(1, ticks - 1) if rng.random() < 0.25 else None
    return Generated(xml, builder.leaves, ticks, halt_before)
