"""SRDF groups as MoveIt reads them: composite groups reference other groups, they do not redefine them."""

from __future__ import annotations

from pathlib import Path

from kinema.motion.srdf import parse_srdf

COMPOSITE = """<?xml version="1.0"?>
<robot name="two_part">
  <group name="arm">
    <chain base_link="base" tip_link="tool"/>
  </group>
  <group name="hand">
    <joint name="finger_joint"/>
    <link name="finger"/>
  </group>
  <group name="arm_and_hand">
    <group name="arm"/>
    <group name="hand"/>
  </group>
  <group_state name="ready" group="arm_and_hand">
    <joint name="finger_joint" value="0.01"/>
  </group_state>
</robot>
"""


def test_a_composite_group_keeps_the_groups_it_names(tmp_path: Path) -> None:
    srdf = tmp_path / "robot.srdf"
    srdf.write_text(COMPOSITE)
    semantic = parse_srdf(srdf)
    assert semantic.groups["arm"].chains == (("base", "tool"),)
    assert semantic.groups["hand"].joints == ("finger_joint",)
    assert semantic.groups["hand"].links == ("finger",)
    assert semantic.groups["arm_and_hand"].subgroups == ("arm", "hand")
    assert semantic.groups["arm_and_hand"].joints == ()
    assert semantic.group_states[("arm_and_hand", "ready")] == {"finger_joint": 0.01}
