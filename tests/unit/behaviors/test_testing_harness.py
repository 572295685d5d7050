"""``kinema.testing.run_objective`` runs an objective as the runtime runs one on its own: the ports it
declares start from their defaults, and overrides replace them (a behavior author's test found the
defaults missing: "unable to find the key [a] remapped to [x]")."""

from __future__ import annotations

import pytest

from kinema.bt import NodeStatus
from kinema.errors import ObjectiveError
from kinema.testing import run_objective

OBJECTIVE = """<root BTCPP_format="4" main_tree_to_execute="Blend">
  <BehaviorTree ID="Blend">
    <Sequence>
      <Sleep msec="{pause}" />
      <SetBlackboard value="{label}" output_key="shown" />
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <SubTree ID="Blend">
      <input_port name="pause" default="1" />
      <input_port name="label" default="sum" />
    </SubTree>
  </TreeNodesModel>
</root>
"""


def test_declared_defaults_are_read_and_overrides_replace_them() -> None:
    run = run_objective(OBJECTIVE)
    assert run.status is NodeStatus.SUCCESS, run.toasts
    assert run.blackboard["pause"] == 1 and run.blackboard["shown"] == "sum"
    run = run_objective(OBJECTIVE, overrides={"pause": "2", "label": "total"})
    assert run.status is NodeStatus.SUCCESS, run.toasts
    assert run.blackboard["pause"] == 2 and run.blackboard["shown"] == "total"


def test_an_override_no_port_reads_is_refused_with_the_parameters() -> None:
    with pytest.raises(ObjectiveError, match=r"reads the blackboard key 'paus'; did you mean 'pause'\?"):
        run_objective(OBJECTIVE, overrides={"paus": "3"})
