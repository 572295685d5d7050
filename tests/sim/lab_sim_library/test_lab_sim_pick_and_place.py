"""MoveIt Pro's "Pick from Pose" (MTC task planning), unchanged, really picks lab_sim's cube in MuJoCo.

The objective is the corpus's own; the test only supplies the grasp pose, as MoveIt Pro's objectives do
(a PoseStamped in the world: above the cube's centre, gripper pointing down), and reads the outcome from
the simulator, not from the plan.
"""

from __future__ import annotations

import time
from typing import Any

import pytest

from conftest import LibraryCell

pytestmark = pytest.mark.slow

RUN_TIMEOUT = 300.0
PICK = """<root BTCPP_format="4" main_tree_to_execute="Pick the Cube">
  <BehaviorTree ID="Pick the Cube">
    <Sequence>
      <SubTree ID="Open Gripper" />
      <Action ID="CreatePoseStamped" reference_frame="world" position_xyz="{x};{y};{z}"
              orientation_xyzw="0;1;0;0" pose_stamped="{{grasp_pose}}" />
      <SubTree ID="Pick from Pose" grasp_pose="{{grasp_pose}}" approach_distance="0.1"
               retract_xyz="0;0;-0.1" />
    </Sequence>
  </BehaviorTree>
</root>"""


def cube_position(cell: LibraryCell) -> tuple[float, float, float]:
    bodies = cell.node.create_client("kinema_msgs/srv/GetSimBodies", "/mujoco/bodies")
    p = next(b for b in bodies.call({}, timeout=10.0).bodies if b.name == "cube").pose.position
    return (float(p.x), float(p.y), float(p.z))


def settled_cube(cell: LibraryCell) -> tuple[float, float, float]:
    """The cube's position once it stops moving (it may still swing in the gripper)."""
    previous = cube_position(cell)
    deadline = time.monotonic() + 10.0
    while time.monotonic() < deadline:
        time.sleep(0.2)
        current = cube_position(cell)
        if max(abs(a - b) for a, b in zip(current, previous, strict=True)) < 1e-4:
            return current
        previous = current
    return previous


def test_pick_from_pose_lifts_the_cube_off_the_table(library_cell: LibraryCell) -> None:
    x, y, z = cube_position(library_cell)
    # The grasp link sits 2 cm above the cube's centre, as in lab_sim's own pick waypoint.
    result: Any = library_cell.client.start(xml=PICK.format(x=x, y=y, z=z + 0.02)).result(RUN_TIMEOUT)
    assert result.succeeded, result
    after = settled_cube(library_cell)
    lifted = after[2] - z
    assert lifted >= 0.05, f"the cube went from {(x, y, z)} to {after}: lifted {lifted:.3f} m"
