"""The tray-place half of MoveIt Pro's ``Pick All Bottles with AprilTags`` on Kinema's lab_sim headless:
look at the tray, find its tag in the wrist camera's image, lay out the six slots. The slots must lie
where the scene's tray has them (1 cm) and inside its walls. Without OpenGL these skip."""

from __future__ import annotations

import runpy

import numpy as np
import pytest
import yaml
from lab_sim_library_cell import LibraryCell
from test_lab_sim_apriltags import RUN_TIMEOUT, cell  # noqa: F401  (the camera-ready fixture)

from kinema.resources import bundled_dir

pytestmark = pytest.mark.slow

GENERATOR = runpy.run_path(str(bundled_dir("configs") / "lab_sim" / "description" / "generate.py"))

# The objective's "Compute Tray Place Positions" sequence, its values unchanged, then the six poses saved.
TRAY_PLACE_TEMPLATE = """<root BTCPP_format="4" main_tree_to_execute="Tray Place Test">
  <BehaviorTree ID="Tray Place Test">
    <Sequence>
      <SubTree ID="Move to Waypoint" waypoint_name="Look at Tray"/>
      <SubTree ID="Take Wrist Camera Image" wrist_camera_image="{tray_image}"
               wrist_camera_info="{camera_info}"/>
      <Action ID="DetectAprilTags" image="{tray_image}" camera_info="{camera_info}"
              detections="{tray_detections}"
              apriltag_family_name="36h11" max_hamming="0" n_threads="1" quad_decimate="2.0" quad_sigma="0.0"
              refine_edges="true" tag_size="0.064"/>
      <Action ID="ComputeTrayPlacePositionsUsingAprilTags" detections="{tray_detections}"
              camera_info="{camera_info}" input_image="{tray_image}" tray_apriltag_id="1" num_rows="3"
              columns_per_row="2" row_spacing="0.10" column_spacing="0.09" tag_to_tray_center="0.125"
              bottle_diameter="0.04" place_positions="{place_positions}"
              visualization_topic="/apriltag_detections"/>
{saves}    </Sequence>
  </BehaviorTree>
</root>"""
SAVE_SLOT = """      <Action ID="GetElementOfVector" vector_in="{{place_positions}}" index="{i}"
              element="{{slot}}"/>
      <Action ID="SavePoseStampedToYaml" message="{{slot}}" yaml_filename="tray_slot_{i}"/>
"""
TRAY_PLACE = TRAY_PLACE_TEMPLATE.replace("{saves}", "".join(SAVE_SLOT.format(i=i) for i in range(6)))


def tray_centre() -> np.ndarray:
    """Where MuJoCo has the tray (a fixed body, so the driver's moving-body service does not list it)."""
    import mujoco

    scene = bundled_dir("configs") / "lab_sim" / "description" / "lab_sim_scene.xml"
    model = mujoco.MjModel.from_xml_path(str(scene))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return np.array(data.body("tray").xpos)


def test_tray_place_positions_lie_in_the_trays_slots(cell: LibraryCell) -> None:  # noqa: F811
    result = cell.client.do_xml(TRAY_PLACE, timeout=RUN_TIMEOUT)
    assert result.success, f"the tray-place sequence failed: {result.message}"
    found = []
    for i in range(6):
        saved = next(cell.objectives.glob(f"tray_slot_{i}.*"), None)
        assert saved is not None, f"no saved slot {i} in {sorted(cell.objectives.iterdir())}"
        data = yaml.safe_load(saved.read_text())
        assert data["header"]["frame_id"] == "world", data["header"]
        p = data["pose"]["position"]
        found.append([p["x"], p["y"], p["z"]])
    found_xyz = np.array(found)
    centre = tray_centre()
    # The slots as the scene lays them out: rows along world x, the two slots of a row along world y,
    # the tag on the tray's -y side (generate.py), at the tray floor's top.
    floor = GENERATOR["TABLE_TOP"] + GENERATOR["TRAY_FLOOR"]
    intended = np.array(
        [[centre[0] + dx, centre[1] + dy, floor] for dx in (-0.10, 0.0, 0.10) for dy in (-0.045, 0.045)]
    )
    errors = np.linalg.norm(found_xyz - intended, axis=1)
    report = (
        f"found {found_xyz.round(4).tolist()}, intended {intended.round(4).tolist()}, "
        f"errors {errors.round(4)}"
    )
    print(report)
    assert errors.max() < 0.01, report
    ix, iy = GENERATOR["TRAY_INNER_HALF"]
    radius = 0.02
    inside = (np.abs(found_xyz[:, 0] - centre[0]) + radius <= ix) & (
        np.abs(found_xyz[:, 1] - centre[1]) + radius <= iy
    )
    assert inside.all(), f"bottles would overlap the tray's walls: {report}"
