"""A SubTree the objective marks ``_collapsed="true"`` opens folded, as in MoveIt Pro's editor."""

from __future__ import annotations

import asyncio

from textual.app import App, ComposeResult

from kinema.tui.tree_outline import build_outline
from kinema.tui.widgets.behavior_tree_view import BehaviorTreeView

XML = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <SubTree ID="Step" _collapsed="true"/>
      <SubTree ID="Step" name="open one"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Step"><Sequence><AlwaysSuccess/><AlwaysSuccess/></Sequence></BehaviorTree>
</root>"""


class _Host(App[None]):
    def compose(self) -> ComposeResult:
        yield BehaviorTreeView()


def test_a_collapsed_subtree_opens_folded_and_the_others_open() -> None:
    async def scenario() -> dict[str, bool]:
        app = _Host()
        async with app.run_test(size=(80, 24)) as pilot:
            view = app.query_one(BehaviorTreeView)
            view.show_outline(build_outline(XML, "Main"))
            await pilot.pause()
            found: dict[str, bool] = {}
            stack = [view.root]
            while stack:
                item = stack.pop()
                node = item.data
                if node is not None and node.is_subtree:
                    found[node.name or "unnamed"] = item.is_expanded
                stack.extend(item.children)
            return found

    assert asyncio.run(scenario()) == {"unnamed": False, "open one": True}
