"""A fresh graph query does not hand back a partial graph that the network answered too early."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from kinema.transport import query_graph
from kinema.transport.keys import node_token

AGENT = node_token(0, "a1", 0, "/", "agent")
DRIVER = node_token(0, "a1", 1, "/sim", "driver")
OBSERVER = node_token(0, "b2", 0, "/", "observer")


class _Liveliness:
    """Answers each query with the next list of keys (the last one again when they run out)."""

    def __init__(self, answers: list[list[str]]) -> None:
        self.answers = answers
        self.queries = 0

    def get(self, _selector: str, timeout: float) -> list[Any]:
        keys = self.answers[min(self.queries, len(self.answers) - 1)]
        self.queries += 1
        return [SimpleNamespace(ok=SimpleNamespace(key_expr=key)) for key in keys]


def _session(liveliness: _Liveliness, known: set[str] | None) -> Any:
    cache = None if known is None else SimpleNamespace(keys=lambda: set(known))
    return SimpleNamespace(
        domain_id=0,
        zid="b2",
        node_count=lambda: 1,
        live_graph_cache=lambda: cache,
        zenoh=SimpleNamespace(liveliness=lambda: liveliness),
    )


def test_an_answer_without_a_node_the_live_graph_knows_is_asked_again() -> None:
    liveliness = _Liveliness([[DRIVER, OBSERVER], [AGENT, DRIVER, OBSERVER]])
    graph = query_graph(_session(liveliness, {AGENT, DRIVER, OBSERVER}), timeout=2)
    assert sorted(graph.nodes()) == ["/agent", "/observer", "/sim/driver"]
    assert liveliness.queries == 2


def test_a_complete_answer_is_taken_at_once_and_without_a_live_graph_own_nodes_suffice() -> None:
    liveliness = _Liveliness([[DRIVER, OBSERVER]])
    assert sorted(query_graph(_session(liveliness, None), timeout=2).nodes()) == ["/observer", "/sim/driver"]
    assert liveliness.queries == 1
