"""MoveIt Pro's AprilTag objectives, unchanged, on Kinema's lab_sim headless (the wrist camera renders
through EGL; without OpenGL these skip with the packages to install).

``Get AprilTag Pose from Image`` must find the block's tag where MuJoCo has it (1 cm, 3 degrees), and
``Pick April Tag Labeled Object`` must lift the block off the table.
"""

from __future__ import annotations

import runpy
import time
from typing import Any

import numpy as np
import pytest
import yaml
from lab_sim_library_cell import LibraryCell, wait_for
from scipy.spatial.transform import Rotation

from kinema.resources import bundled_dir

pytestmark = pytest.mark.slow

RUN_TIMEOUT = 240.0
GENERATOR = runpy.run_path(str(bundled_dir("configs") / "lab_sim" / "description" / "generate.py"))
BLOCK = next(o for o in GENERATOR["TAGGED_OBJECTS"] if o.name == "tag_block")

# A harness around the subtree (MoveIt Pro marks it not runnable: it maps an image to a pose): look at
# the table, take the wrist camera's picture, find the tag, save its world pose for the test to read.
FIND_TAG = """<root BTCPP_format="4" main_tree_to_execute="Find Tag Test">
  <BehaviorTree ID="Find Tag Test">
    <Sequence>
      <SubTree ID="Look at Table"/>
      <SubTree ID="Take Wrist Camera Image" wrist_camera_image="{image}" wrist_camera_info="{camera_info}"/>
      <SubTree ID="Get AprilTag Pose from Image" image="{image}" camera_info="{camera_info}"
               detection_pose="{detection_pose}"/>
      <Action ID="SavePoseStampedToYaml" message="{detection_pose}" yaml_filename="found_tag_pose"/>
    </Sequence>
  </BehaviorTree>
</root>"""


@pytest.fixture(scope="module")
def cell(library_cell: LibraryCell) -> LibraryCell:
    """The library cell, with its cameras rendering (else the tests skip, naming what to install)."""
    library_cell.render_each_camera_once((("sensor_msgs/msg/Image", "/wrist_camera/color"),), 60.0)
    return library_cell


def body_pose(cell: LibraryCell, name: str) -> np.ndarray:
    """The 4x4 world pose of a MuJoCo body, from the driver's /mujoco/bodies service."""
    from kinema.drivers.mujoco import names

    client = cell.node.create_client(names.BODIES_TYPE, names.BODIES_SERVICE)
    bodies = {str(b.name): b.pose for b in client.call({}, timeout=10.0).bodies}
    assert name in bodies, f"no body {name!r} in the simulation: {sorted(bodies)}"
    pose = bodies[name]
    matrix = np.eye(4)
    q = pose.orientation
    matrix[:3, :3] = Rotation.from_quat([q.x, q.y, q.z, q.w]).as_matrix()
    matrix[:3, 3] = [pose.position.x, pose.position.y, pose.position.z]
    return matrix


def tag_pose(cell: LibraryCell) -> np.ndarray:
    """Where the block's tag is: the top face of its 1 mm box on the block's top face."""
    offset = np.eye(4)
    offset[2, 3] = BLOCK.half[2] + GENERATOR["TAG_THICKNESS"]
    return body_pose(cell, "tag_block") @ offset


def test_get_april_tag_pose_from_image_finds_the_block_tag_where_it_is(cell: LibraryCell) -> None:
    result = cell.client.do_xml(FIND_TAG, timeout=RUN_TIMEOUT)
    assert result.success, f"the tag-finding objective failed: {result.message}"
    saved = next(cell.objectives.glob("found_tag_pose*"), None)
    assert saved is not None, f"no saved pose in {cell.objectives}"
    data = yaml.safe_load(saved.read_text())
    assert data["header"]["frame_id"] == "world", data["header"]
    p, q = data["pose"]["position"], data["pose"]["orientation"]
    found = np.eye(4)
    found[:3, :3] = Rotation.from_quat([q["x"], q["y"], q["z"], q["w"]]).as_matrix()
    found[:3, 3] = [p["x"], p["y"], p["z"]]
    truth = tag_pose(cell)
    distance = float(np.linalg.norm(found[:3, 3] - truth[:3, 3]))
    angle = float(np.degrees(Rotation.from_matrix(truth[:3, :3].T @ found[:3, :3]).magnitude()))
    report = (
        f"found {found[:3, 3].round(4)}, MuJoCo has {truth[:3, 3].round(4)}: "
        f"{distance * 1000:.1f} mm, {angle:.2f} deg"
    )
    assert distance < 0.01 and angle < 3.0, report


def test_apriltag_pick_object_lifts_the_block(cell: LibraryCell) -> None:
    rest = body_pose(cell, "tag_block")[:3, 3]
    result = cell.client.execute("Pick April Tag Labeled Object", timeout=RUN_TIMEOUT)
    assert result.success, f"Pick April Tag Labeled Object failed: {result.message}"
    lifted = wait_for(
        lambda: (z := body_pose(cell, "tag_block")[2, 3]) > rest[2] + 0.05 and z,
        10.0,
        "the block above the table",
    )
    time.sleep(1.0)  # held, not tossed: still up a moment later
    held = body_pose(cell, "tag_block")[:3, 3]
    assert held[2] > rest[2] + 0.05, (
        f"the block fell back: rested at z={rest[2]:.3f}, lifted to {lifted:.3f}, now {held}"
    )


def reset_scene(cell: LibraryCell) -> None:
    """Robot and objects back to the "default" keyframe (the block on the table, the gripper open)."""
    from kinema.drivers.mujoco import names

    client = cell.node.create_client(names.SET_STATE_TYPE, names.SET_STATE_SERVICE)
    response = client.call({"keyframe": "default"}, timeout=10.0)
    assert response.success, response.message


def test_the_approval_variant_picks_with_approvals_granted_headless(
    cell: LibraryCell, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Headless with ``--auto-approve`` (KINEMA_AUTO_APPROVE=1 in the agent's process): the approval the
    objective asks for is granted and the block is picked."""
    reset_scene(cell)
    rest = np.array(
        wait_for(
            lambda: (p := body_pose(cell, "tag_block")[:3, 3])[2] < BLOCK.start[2] + 0.01 and tuple(p),
            10.0,
            "the block back on the table",
        )
    )
    monkeypatch.setenv("KINEMA_AUTO_APPROVE", "1")
    result = cell.client.execute("Pick April Tag Labeled Object With Approval", timeout=RUN_TIMEOUT)
    assert result.success, f"Pick April Tag Labeled Object With Approval failed: {result.message}"
    held = np.array(
        wait_for(
            lambda: (p := body_pose(cell, "tag_block")[:3, 3])[2] > rest[2] + 0.05 and tuple(p),
            10.0,
            "the block lifted",
        )
    )
    assert np.linalg.norm(held[:2] - rest[:2]) < 0.05, f"picked up from {rest}, now at {held}"


def test_the_tui_connection_lists_and_watches_the_wrist_camera(cell: LibraryCell) -> None:
    """What the TUI's camera view gets from a real runtime: the image topics, then RGB pictures."""
    from kinema.tui.connection import ConnectionChanged, ConnectionState
    from kinema.tui.sdk_connection import SdkConnection

    states: list[ConnectionState] = []
    connection = SdkConnection(endpoint=cell.endpoint, config="lab_sim")
    connection.open(lambda event: isinstance(event, ConnectionChanged) and states.append(event.state))
    try:
        wait_for(lambda: ConnectionState.CONNECTED in states, 30.0, "the TUI connection to connect")
        expected = {"/wrist_camera/color", "/scene_camera/color", "/wrist_camera/depth"}
        # Discovery takes its time on a loaded machine (the view has a refresh key for that): wait for it.
        listed: list[list[str]] = []
        try:
            wait_for(
                lambda: listed.append(connection.image_topics()) or expected <= set(listed[-1]),
                30.0,
                f"{sorted(expected)} among the listed image topics",
            )
        except AssertionError as error:
            raise AssertionError(f"{error}; last listed: {listed[-1] if listed else None}") from None
        pictures: list[Any] = []
        stop = connection.watch_images("/wrist_camera/depth", pictures.append)
        try:
            picture = wait_for(lambda: pictures and pictures[-1], 30.0, "a depth picture for the TUI")
        finally:
            stop()
        assert picture.pixels.shape == (480, 640, 3) and picture.encoding == "32FC1"
        assert picture.frame_id == "wrist_camera_optical_frame"
        assert len(np.unique(picture.pixels[:, :, 0])) > 10, "depth is shaded, not flat"
    finally:
        connection.close()
