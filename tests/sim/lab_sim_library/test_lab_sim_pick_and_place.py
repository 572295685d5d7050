"""MoveIt Pro's MTC objectives, unchanged, on lab_sim in MuJoCo: "Pick from Pose" lifts the cube, "Place
at Pose" sets it down where asked, "Move Along Square" traces its square.

The objectives are the corpus's own; the tests only supply the poses, as MoveIt Pro's objectives do (a
PoseStamped in the world, gripper pointing down), and read the outcome from the simulator (MuJoCo's cube,
the joint states it publishes), not from the plan.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

import pytest

if TYPE_CHECKING:  # annotations only: importing conftest by name clashes with other test folders'
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


PLACE = """<root BTCPP_format="4" main_tree_to_execute="Place the Cube">
  <BehaviorTree ID="Place the Cube">
    <Sequence>
      <Action ID="CreatePoseStamped" reference_frame="world" position_xyz="{x};{y};{z}"
              orientation_xyzw="0;1;0;0" pose_stamped="{{place_pose}}" />
      <SubTree ID="Place at Pose" place_pose="{{place_pose}}" approach_distance="0.1"
               retract_xyz="0;0;-0.1" />
    </Sequence>
  </BehaviorTree>
</root>"""
GRASP_ABOVE_CENTRE = 0.02  # the grasp link sits 2 cm above the cube's centre, as at lab_sim's pick waypoint


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


def test_pick_from_pose_lifts_the_cube_and_place_at_pose_sets_it_down_where_asked(
    library_cell: LibraryCell,
) -> None:
    x, y, z = cube_position(library_cell)
    pick = PICK.format(x=x, y=y, z=z + GRASP_ABOVE_CENTRE)
    result: Any = library_cell.client.start(xml=pick).result(RUN_TIMEOUT)
    assert result.succeeded, result
    after = settled_cube(library_cell)
    lifted = after[2] - z
    assert lifted >= 0.05, f"the cube went from {(x, y, z)} to {after}: lifted {lifted:.3f} m"

    asked = (x + 0.05, y - 0.15, z)  # on the table, 15 cm to the side
    place = PLACE.format(x=asked[0], y=asked[1], z=asked[2] + GRASP_ABOVE_CENTRE)
    result = library_cell.client.start(xml=place).result(RUN_TIMEOUT)
    assert result.succeeded, result
    down = settled_cube(library_cell)
    error = max(abs(a - b) for a, b in zip(down, asked, strict=True))
    assert error <= 0.02, f"asked to place the cube at {asked}, it is at {down} ({error:.3f} m off)"


def test_move_along_square_traces_a_square_through_its_corners(library_cell: LibraryCell) -> None:
    import numpy as np

    from kinema.motion import RobotDescription, fk

    model = RobotDescription.lab_sim().load_model()
    assert library_cell.client.execute("Look at Table", timeout=RUN_TIMEOUT).succeeded
    states = library_cell.listen("sensor_msgs/msg/JointState", "/joint_states")
    _fresh(states)
    seen = len(states)
    start = _tool(model, states[-1], fk)
    result = library_cell.client.execute("Move Along Square", timeout=RUN_TIMEOUT)
    assert result.succeeded, result
    _fresh(states)
    path = np.array([_tool(model, message, fk) for message in states[seen:]])
    corners = start + np.array([[0, 0.2, 0], [0.2, 0.2, 0], [0.2, 0, 0], [0, 0, 0]])
    misses = [_closest_pass(path, corner) for corner in corners]
    assert max(misses) <= 0.005, f"closest passes by the corners (m): {np.round(misses, 4).tolist()}"


def _closest_pass(path: Any, point: Any) -> float:
    """How close the tool's path comes to ``point``: the path is the polyline through the sampled tool
    positions, so a joint state the best-effort topic dropped near a corner does not count as a miss."""
    import numpy as np

    if len(path) == 1:
        return float(np.linalg.norm(path[0] - point))
    starts, ends = path[:-1], path[1:]
    steps = ends - starts
    lengths = np.einsum("ij,ij->i", steps, steps)
    along = np.einsum("ij,ij->i", point - starts, steps) / np.where(lengths > 0, lengths, 1.0)
    nearest = starts + np.clip(along, 0.0, 1.0)[:, None] * steps
    return float(np.linalg.norm(nearest - point, axis=1).min())


def _fresh(states: list[Any], timeout: float = 10.0) -> None:
    """Wait for a joint state newer than the ones already received."""
    seen = len(states)
    deadline = time.monotonic() + timeout
    while len(states) <= seen:
        assert time.monotonic() < deadline, f"no joint state within {timeout} s"
        time.sleep(0.02)


def _tool(model: Any, message: Any, fk: Any) -> Any:
    positions = dict(zip(message.name, message.position, strict=True))
    q = model.configuration({n: v for n, v in positions.items() if n in model.joint_names})
    return fk(model, q, "tool0")[:3, 3]


# Yaw-equivalent top-down grasps (0, 90, 180, 270 degrees about the world z axis), as "Pick from Pose
# Vector" expects them: batch IK takes the one closest to where the arm is.
YAWS = ("0;1;0;0", "-0.7071068;0.7071068;0;0", "-1;0;0;0", "-0.7071068;-0.7071068;0;0")


def _pose_vector(key: str, x: float, y: float, z: float) -> str:
    lines = [f'<Action ID="ResetPoseStampedVector" vector="{{{key}}}" />']
    for yaw in YAWS:
        lines.append(
            f'<Action ID="CreatePoseStamped" reference_frame="world" position_xyz="{x};{y};{z}" '
            f'orientation_xyzw="{yaw}" pose_stamped="{{candidate}}" />'
        )
        lines.append(
            f'<Action ID="PushBackVector" input_vector="{{{key}}}" element="{{candidate}}" '
            f'output_vector="{{{key}}}" />'
        )
    return "\n".join(lines)


def test_pick_from_pose_vector_and_place_with_approval_move_the_cube_headless(
    library_cell: LibraryCell,
) -> None:
    """Nobody is attached to approve: "Wait for Trajectory Approval if User Available" goes on without
    asking (the headless rule), so MoveIt Pro's "Place at Pose with Approval" runs through."""
    x, y, z = cube_position(library_cell)
    pick = f"""<root BTCPP_format="4" main_tree_to_execute="Pick Any Yaw">
      <BehaviorTree ID="Pick Any Yaw"><Sequence>
        <SubTree ID="Open Gripper" />
        {_pose_vector("grasp_poses", x, y, z + GRASP_ABOVE_CENTRE)}
        <SubTree ID="Pick from Pose Vector" grasp_poses="{{grasp_poses}}" approach_distance="0.1"
                 retract_xyz="0;0;-0.1" />
      </Sequence></BehaviorTree></root>"""
    result: Any = library_cell.client.start(xml=pick).result(RUN_TIMEOUT)
    assert result.succeeded, result
    held = settled_cube(library_cell)
    assert held[2] - z >= 0.05, f"the cube went from {(x, y, z)} to {held}"

    asked = (x - 0.05, y + 0.1, z)
    place = f"""<root BTCPP_format="4" main_tree_to_execute="Place Any Yaw">
      <BehaviorTree ID="Place Any Yaw"><Sequence>
        {_pose_vector("place_poses", asked[0], asked[1], asked[2] + GRASP_ABOVE_CENTRE)}
        <SubTree ID="Place at Pose with Approval" place_poses="{{place_poses}}" />
      </Sequence></BehaviorTree></root>"""
    result = library_cell.client.start(xml=place).result(RUN_TIMEOUT)
    assert result.succeeded, result
    down = settled_cube(library_cell)
    error = max(abs(a - b) for a, b in zip(down, asked, strict=True))
    assert error <= 0.02, f"asked to place the cube at {asked}, it is at {down} ({error:.3f} m off)"
