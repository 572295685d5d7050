"""The SDK's blackboard snapshot reads like a mapping of parsed values; scopes are there when needed."""

from __future__ import annotations

import pytest

from kinema.sdk import BlackboardSnapshot, BlackboardValue


def snapshot() -> BlackboardSnapshot:
    entries = (
        BlackboardValue("Add Numbers", "sum", "int", "42"),
        BlackboardValue("Add Numbers", "ratio", "double", "0.5"),
        BlackboardValue("Add Numbers", "label", "std::string", "'42'"),
        BlackboardValue("Add Numbers", "done", "bool", "true"),
        BlackboardValue("Add Numbers", "joints", "std::vector<double>", "[0.1, 0.2]"),
        BlackboardValue(
            "Add Numbers", "pose", "geometry_msgs/msg/PoseStamped", "{header: {frame_id: world}}"
        ),
        BlackboardValue("Add Numbers/Inner::3", "y", "double", "2.0"),
        BlackboardValue("Add Numbers/Inner::3", "sum", "int", "7"),
        BlackboardValue("Other::5", "y", "double", "3.0"),
        BlackboardValue("Other::5", "only_here", "std::string", "not: yaml: at all"),
    )
    return BlackboardSnapshot("Add Numbers", 12.5, entries)


def test_values_are_parsed_into_python_types() -> None:
    snap = snapshot()
    assert snap["sum"] == 42 and type(snap["sum"]) is int
    assert snap["ratio"] == 0.5 and snap["done"] is True
    assert snap["label"] == "42", "a std::string stays a string even when it looks like a number"
    assert snap["joints"] == [0.1, 0.2]
    assert snap["pose"] == {"header": {"frame_id": "world"}}
    assert snap["only_here"] == "not: yaml: at all", "found in the only scope that has it; raw text kept"


def test_typed_access() -> None:
    snap = snapshot()
    total: int = snap.value("sum", int)
    assert total == 42
    assert snap.value("sum", float) == 42.0
    with pytest.raises(TypeError, match=r"'label' holds '42' \(std::string\), not an int"):
        snap.value("label", int)
    with pytest.raises(TypeError):
        snap.value("done", int)


def test_root_scope_first_subtree_scopes_on_request() -> None:
    snap = snapshot()
    assert snap.scopes == ["Add Numbers", "Add Numbers/Inner::3", "Other::5"]
    assert snap["sum"] == 42, "the root's own key wins over a subtree's"
    assert snap.scope("Add Numbers/Inner::3") == {"y": 2.0, "sum": 7}
    with pytest.raises(KeyError, match=r"'y' is in several scopes \(Add Numbers/Inner::3, Other::5\)"):
        snap["y"]
    with pytest.raises(KeyError, match=r"no blackboard key 'summ'.*sum"):
        snap["summ"]
    with pytest.raises(KeyError, match="no blackboard scope 'Nope'; scopes: Add Numbers"):
        snap.scope("Nope")
    assert snap.get("summ", 0) == 0 and "sum" in snap and "summ" not in snap
    assert snap.keys()[:2] == ["sum", "ratio"]
