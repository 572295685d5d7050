"""Perception behaviors MoveIt Pro's example workspace uses, batch D: what an objective sees.

GetGraspableObjectsFromMasks3D and ExtractGraspableObjectPose (a door, a handle, a button becomes a box and
the pose a push goes to), FitLineSegmentToMask3D (a hinge, a lever handle), GetMask2DProperties and
FilterMasks2DByArea (mask areas in pixels), and the model-running GetMasks2DAction and GetMasks2DAutomask,
which fail saying Kinema runs no segmentation model. Then each example objective's calls, port for port,
validated against lab_sim.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from kinema.bt import NodeStatus
from kinema.perception import PointCloud
from kinema.perception.ros_messages import to_point_cloud2
from kinema.testing import run_objective, tick_behavior
from kinema.transforms import pose_from_message
from kinema.transport import from_dict

MASK2D = "moveit_studio_vision_msgs/msg/Mask2D"
MASK3D = "moveit_studio_vision_msgs/msg/Mask3D"
# Ports as "Push Button ML" sets them.
PUSH_BUTTON_ML = {
    "base_frame": "world",
    "plane_inlier_threshold": 0.02,
    "minimum_face_area": 0.000625,
    "face_separation_threshold": 0.03,
}


def _types() -> Any:
    from kinema.interfaces import load_interfaces

    return load_interfaces().typestore.types


def cloud_message(points: Any) -> Any:
    """An unorganised cloud in ``world``: the camera that took it is at the world's origin."""
    return to_point_cloud2(PointCloud(np.asarray(points, dtype=np.float32), None, "world", 0.0), _types())


def mask3d(indices: Any) -> Any:
    return from_dict(
        MASK3D, {"header": {"frame_id": "world"}, "point_indices": np.asarray(indices, np.uint32)}
    )


def mask2d(pixels: np.ndarray, x: int = 0, y: int = 0) -> Any:
    """A Mask2D of the boolean image ``pixels`` whose top-left pixel is (x, y)."""
    rows, cols = pixels.shape
    image = {
        "height": rows,
        "width": cols,
        "encoding": "mono8",
        "step": cols,
        "data": np.where(pixels, 255, 0).astype(np.uint8).ravel(),
    }
    return from_dict(MASK2D, {"x": x, "y": y, "mask": image})


def block(rows: int, cols: int, height: int = 0, width: int = 0) -> np.ndarray:
    """A ``rows`` x ``cols`` block of object pixels in a ``height`` x ``width`` mask image (0: no margin)."""
    image = np.zeros((max(rows, height), max(cols, width)), dtype=bool)
    image[:rows, :cols] = True
    return image


def grid(x: float, ys: tuple[float, float], zs: tuple[float, float], step: float = 0.005) -> np.ndarray:
    """Points of the rectangle at depth ``x`` (m) spanning ``ys`` and ``zs``: a face the camera looks at."""
    y, z = np.meshgrid(np.arange(ys[0], ys[1] + 1e-9, step), np.arange(zs[0], zs[1] + 1e-9, step))
    return np.stack([np.full(y.size, x), y.ravel(), z.ravel()], axis=1)


# -- GetGraspableObjectsFromMasks3D and ExtractGraspableObjectPose ----------------------------------------


def _button_scene() -> tuple[np.ndarray, list[Any]]:
    """A 4 x 3 cm button face 1 m in front of the camera, with the wall 0.5 m behind it seen past its edge
    (a column of pixels); a 1 x 1 cm speck; two stray points."""
    button = grid(1.0, (0.10, 0.14), (0.30, 0.33))
    wall = grid(1.5, (0.15, 0.15), (0.30, 0.33))
    speck = grid(0.9, (-0.2, -0.19), (0.0, 0.01))
    stray = np.array([[2.0, 0.0, 0.0], [2.0, 0.1, 0.0]])
    points = np.vstack([button, wall, speck, stray])
    ends = np.cumsum([0, len(button), len(wall), len(speck), len(stray)])
    masks = [
        mask3d(np.arange(ends[0], ends[2])),  # the button and the wall behind it
        mask3d(np.arange(ends[2], ends[3])),
        mask3d(np.arange(ends[3], ends[4])),
    ]
    return points, masks


def test_a_button_becomes_a_box_whose_pose_faces_into_it_from_the_camera(behavior: Any) -> None:
    points, masks = _button_scene()
    run = tick_behavior(
        behavior("GetGraspableObjectsFromMasks3D"),
        {"point_cloud": cloud_message(points), "masks3d": masks, **PUSH_BUTTON_ML},
    )
    assert run.status is NodeStatus.SUCCESS, run.toasts
    # The speck's face (1 cm²) is below minimum_face_area, the two strays fit no face: one object.
    (button,) = run.outputs["graspable_objects"]
    assert any("mask 1: face of" in t and "mask 2:" in t for t in run.toasts), run.toasts
    box = button.object
    assert box.id == "object_0" and box.header.frame_id == "world"
    # 4 cm along its longest side, 3 cm across, as thick as plane_inlier_threshold: the wall is not in it.
    np.testing.assert_allclose(box.primitives[0].dimensions, [0.04, 0.03, 0.02], atol=1e-6)

    pose = tick_behavior(behavior("ExtractGraspableObjectPose"), {"graspable_object": button})
    assert pose.status is NodeStatus.SUCCESS, pose.toasts
    stamped = pose.outputs["pose"]
    matrix = pose_from_message(stamped.pose)
    assert stamped.header.frame_id == "world"
    np.testing.assert_allclose(matrix[:3, 3], [1.01, 0.12, 0.315], atol=1e-6)
    # z points away from the camera into the button (Push Button ML pushes along it); x along its width.
    np.testing.assert_allclose(matrix[:3, 2], [1.0, 0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(matrix[:3, 0], [0.0, 1.0, 0.0], atol=1e-6)


def test_the_object_goes_into_the_planning_scene_where_its_pose_says(behavior: Any) -> None:
    """Generate Graspable Object's path: UnpackGraspableObjectMessage → AddCollisionObject."""
    from kinema.motion.planning_scene_messages import primitives_of

    points, masks = _button_scene()
    run = tick_behavior(
        behavior("GetGraspableObjectsFromMasks3D"),
        {"point_cloud": cloud_message(points), "masks3d": masks[:1], **PUSH_BUTTON_ML},
    )
    (button,) = run.outputs["graspable_objects"]
    unpacked = tick_behavior(behavior("UnpackGraspableObjectMessage"), {"graspable_object": button})
    (placed,) = primitives_of(unpacked.outputs["object"], None)
    np.testing.assert_allclose(placed.world_T_object[:3, 3], [1.01, 0.12, 0.315], atol=1e-6)


def test_a_door_seen_with_its_frame_is_the_door_and_a_box_from_a_hand_built_object_too(
    behavior: Any,
) -> None:
    """Detect Door Graspable Object's ports: the door is the plane most points lie on; the frame 15 cm
    behind it (beyond face_separation_threshold) is not the door's."""
    door = grid(1.2, (-0.2, 0.2), (0.0, 0.8), step=0.02)
    frame = grid(1.35, (0.22, 0.26), (0.0, 0.8), step=0.02)
    run = tick_behavior(
        behavior("GetGraspableObjectsFromMasks3D"),
        {
            "point_cloud": cloud_message(np.vstack([door, frame])),
            "masks3d": [mask3d(np.arange(len(door) + len(frame)))],
            "base_frame": "world",
            "plane_inlier_threshold": 0.01,
            "minimum_face_area": 0.000625,
            "face_separation_threshold": 0.02,
        },
    )
    assert run.status is NodeStatus.SUCCESS, run.toasts
    (found,) = run.outputs["graspable_objects"]
    np.testing.assert_allclose(found.object.primitives[0].dimensions, [0.8, 0.4, 0.01], atol=1e-6)
    pose = pose_from_message(found.object.pose)
    np.testing.assert_allclose(pose[:3, 0], [0.0, 0.0, 1.0], atol=1e-6)  # x up the door, its longest side
    # An object placing its box by the primitive's pose (as CreateCollisionObjectMessage builds one).
    hand_built = from_dict(
        "moveit_studio_vision_msgs/msg/GraspableObject",
        {
            "object": {
                "header": {"frame_id": "world"},
                "pose": {"position": {"x": 1.0}, "orientation": {"w": 1.0}},
                "primitives": [{"type": 1, "dimensions": [0.1, 0.1, 0.1]}],
                "primitive_poses": [{"position": {"z": 0.5}, "orientation": {"w": 1.0}}],
            }
        },
    )
    pose_run = tick_behavior(behavior("ExtractGraspableObjectPose"), {"graspable_object": hand_built})
    position = pose_run.outputs["pose"].pose.position
    assert (position.x, position.y, position.z) == (1.0, 0.0, 0.5)


def test_graspable_objects_refuse_a_mask_of_another_cloud_and_a_negative_threshold(behavior: Any) -> None:
    points, masks = _button_scene()
    small = tick_behavior(
        behavior("GetGraspableObjectsFromMasks3D"),
        {"point_cloud": cloud_message(points[:10]), "masks3d": masks, **PUSH_BUTTON_ML},
    )
    assert small.status is NodeStatus.FAILURE
    assert "lists point" in small.toasts[-1] and "the cloud has 10 points" in small.toasts[-1]
    negative = tick_behavior(
        behavior("GetGraspableObjectsFromMasks3D"),
        {"point_cloud": cloud_message(points), "masks3d": masks, **PUSH_BUTTON_ML, "minimum_face_area": -1.0},
    )
    assert negative.status is NodeStatus.FAILURE and "port [minimum_face_area] = -1" in negative.toasts[-1]


# -- FitLineSegmentToMask3D ---------------------------------------------------------------------------------


def test_a_hinge_becomes_the_segment_between_its_ends_despite_the_door_beside_it(behavior: Any) -> None:
    rng = np.random.default_rng(3)
    heights = np.linspace(0.3, 0.8, 101)
    hinge = np.stack([np.full(101, 1.0), np.full(101, 0.2), heights], axis=1)
    hinge += rng.normal(0.0, 0.002, hinge.shape)
    door = grid(1.0, (0.25, 0.4), (0.3, 0.6), step=0.05)  # part of the door inside the hinge's mask
    points = np.vstack([hinge, door])
    run = tick_behavior(
        behavior("FitLineSegmentToMask3D"),
        {
            "point_cloud": cloud_message(points),
            "mask3d": mask3d(np.arange(len(points))),
            "base_frame": "world",
            "max_distance_from_line_for_inlier": 0.02,
        },
    )
    assert run.status is NodeStatus.SUCCESS, run.toasts
    start, end = (pose_from_message(p.pose) for p in run.outputs["line_segment_poses"])
    assert all(p.header.frame_id == "world" for p in run.outputs["line_segment_poses"])
    # Bottom to top, within the noise.
    np.testing.assert_allclose(start[:3, 3], [1.0, 0.2, 0.3], atol=0.01)
    np.testing.assert_allclose(end[:3, 3], [1.0, 0.2, 0.8], atol=0.01)
    np.testing.assert_allclose(start[:3, 0], [0.0, 0.0, 1.0], atol=0.02)  # x along the hinge
    # z from the camera (the origin) towards the hinge, square to it.
    expected_z = np.array([1.0, 0.2, 0.0]) / np.linalg.norm([1.0, 0.2, 0.0])
    np.testing.assert_allclose(start[:3, 2], expected_z, atol=0.02)
    np.testing.assert_allclose(start[:3, :3], end[:3, :3])


def test_a_line_needs_two_points_and_a_distance_of_zero_or_more(behavior: Any) -> None:
    points = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.5]])
    one = tick_behavior(
        behavior("FitLineSegmentToMask3D"), {"point_cloud": cloud_message(points), "mask3d": mask3d([1])}
    )
    assert one.status is NodeStatus.FAILURE
    assert "port [mask3d]" in one.toasts[-1] and "too few distinct points to fit a line: 1" in one.toasts[-1]
    negative = tick_behavior(
        behavior("FitLineSegmentToMask3D"),
        {
            "point_cloud": cloud_message(points),
            "mask3d": mask3d([0, 1]),
            "max_distance_from_line_for_inlier": -0.1,
        },
    )
    assert negative.status is NodeStatus.FAILURE
    assert "port [max_distance_from_line_for_inlier]" in negative.toasts[-1]


# -- GetMask2DProperties and FilterMasks2DByArea ------------------------------------------------------------


def test_mask_properties_are_the_pixel_count_and_the_box_around_the_pixels(behavior: Any) -> None:
    pixels = np.zeros((10, 12), dtype=bool)
    pixels[2:6, 3:10] = True  # 4 rows x 7 columns
    pixels[6, 3] = True  # one more row at the left: 5 rows tall, 29 pixels
    run = tick_behavior(behavior("GetMask2DProperties"), {"mask": mask2d(pixels, x=40, y=30)})
    assert run.status is NodeStatus.SUCCESS, run.toasts
    assert run.outputs == {"width": 7, "height": 5, "area": 29}
    empty = tick_behavior(behavior("GetMask2DProperties"), {"mask": mask2d(np.zeros((3, 3), bool))})
    assert empty.outputs == {"width": 0, "height": 0, "area": 0}


def test_filtering_by_area_keeps_the_masks_between_the_bounds_in_order(behavior: Any) -> None:
    """The areas hangar_sim's calibration measured: an edge fragment, two boxes, the cart frame."""
    fragment, small_box, big_box, cart = (
        mask2d(block(2, 389)),  # 778 px
        mask2d(block(1, 3949)),
        mask2d(block(1, 20643)),
        mask2d(block(1, 26285)),
    )
    masks = [cart, small_box, fragment, big_box]
    run = tick_behavior(
        behavior("FilterMasks2DByArea"), {"masks": masks, "min_area": 2000, "max_area": 23000}
    )
    assert run.status is NodeStatus.SUCCESS, run.toasts
    assert run.outputs["filtered_masks"] == [small_box, big_box]
    exact = tick_behavior(
        behavior("FilterMasks2DByArea"), {"masks": masks, "min_area": 3949, "max_area": 20643}
    )
    assert exact.outputs["filtered_masks"] == [small_box, big_box]  # both bounds kept
    unbounded = tick_behavior(behavior("FilterMasks2DByArea"), {"masks": masks, "min_area": 2000})
    assert unbounded.outputs["filtered_masks"] == [cart, small_box, big_box]
    none = tick_behavior(behavior("FilterMasks2DByArea"), {"masks": masks, "min_area": 30000})
    assert none.status is NodeStatus.SUCCESS and none.outputs["filtered_masks"] == []
    crossed = tick_behavior(
        behavior("FilterMasks2DByArea"), {"masks": masks, "min_area": 5000, "max_area": 100}
    )
    assert crossed.status is NodeStatus.FAILURE
    assert "port [max_area] = 100 is below min_area 5000" in crossed.toasts[-1]
    wrong = tick_behavior(behavior("FilterMasks2DByArea"), {"masks": [mask3d([0])]})
    assert wrong.status is NodeStatus.FAILURE and "element 0 is not a" in wrong.toasts[-1]


def test_calibrate_sam3_mask_areas_loop_labels_each_mask_with_its_area(registry: Any) -> None:
    """The calibration objective's loop over masks (from a model there; given here)."""
    xml = """<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main"><Sequence>
      <Script code="labels := ''"/>
      <Decorator ID="ForEach" vector_in="{masks2d}" index="{idx}" out="{mask}">
        <Sequence>
          <Action ID="GetMask2DProperties" mask="{mask}" width="{w}" height="{h}" area="{area}"/>
          <Script code="labels := labels..&quot; area=&quot;..area..&quot; bbox=&quot;..w..&quot;x&quot;..h"/>
        </Sequence>
      </Decorator>
      <Action ID="FilterMasks2DByArea" masks="{masks2d}" min_area="2000" max_area="23000"
        filtered_masks="{masks2d}"/>
      <Action ID="GetSizeOfVector" vector_in="{masks2d}" vector_size="{mask_count}"/>
    </Sequence></BehaviorTree></root>"""
    masks = [mask2d(block(10, 100)), mask2d(block(50, 60, 55, 70))]
    run = run_objective(xml, registry=registry, overrides={"masks2d": masks})
    assert run.status is NodeStatus.SUCCESS, run.toasts
    assert run.blackboard["labels"] == " area=1000 bbox=100x10 area=3000 bbox=60x50"
    assert run.blackboard["mask_count"] == 1


# -- the segmentation models Kinema does not run ------------------------------------------------------------


@pytest.mark.parametrize(
    ("behavior_id", "inputs", "source"),
    [
        ("GetMasks2DAction", {"action_name": "get_masks_2d_maskrcnn"}, "the get_masks_2d_maskrcnn action"),
        ("GetMasks2DAutomask", {"model_package": "factory_sim"}, "SAM2 automask from factory_sim"),
    ],
)
def test_the_model_behaviors_fail_saying_kinema_runs_no_model_and_write_no_masks(
    behavior: Any, behavior_id: str, inputs: dict[str, Any], source: str
) -> None:
    run = tick_behavior(behavior(behavior_id), inputs)
    assert run.status is NodeStatus.FAILURE
    (toast,) = run.toasts
    assert toast.startswith(f"{behavior_id}: Kinema does not run segmentation models ({source}"), toast
    assert "give masks2d from a behavior of your own" in toast
    assert run.outputs == {}


# -- each example objective's calls, port for port, against lab_sim ----------------------------------------

CAMERA = """
<Action ID="GetCameraInfo" topic_name="/wrist_camera/camera_info" message_out="{camera_info}"/>
<Action ID="GetImage" topic_name="/wrist_camera/color" message_out="{image}"/>
<Action ID="GetPointCloud" topic_name="/wrist_camera/points" message_out="{point_cloud}"/>
"""
MASKS_TO_3D = """
<Action ID="GetMasks3DFromMasks2D" point_cloud="{point_cloud}" masks2d="{MASKS}"
  camera_info="{camera_info}" masks3d="{masks3d}"/>
"""


def _maskrcnn(
    masks: str, timeout: str, classes: str, areas: str = 'min_relative_area="0" max_relative_area="1"'
) -> str:
    return f"""
<Action ID="GetMasks2DAction" image="{{image}}" action_name="get_masks_2d_maskrcnn" min_confidence="0.8"
  max_nms_iou="0.8" {areas} timeout_sec="{timeout}" masks2d="{{{masks}}}" valid_classes="{classes}"/>
{MASKS_TO_3D.replace("MASKS", masks)}"""


def _graspable(inlier: str, area: str, separation: str, out: str, cloud: str = "point_cloud") -> str:
    return f"""
<Action ID="GetGraspableObjectsFromMasks3D" point_cloud="{{{cloud}}}" masks3d="{{masks3d}}" base_frame="world"
  plane_inlier_threshold="{inlier}" minimum_face_area="{area}" face_separation_threshold="{separation}"
  graspable_objects="{{{out}}}"/>"""


def _first(vector: str, out: str) -> str:
    return f"""
<Decorator ID="ForceSuccess"><Decorator ID="ForEach" vector_in="{{{vector}}}" out="{{{out}}}">
  <Action ID="AlwaysFailure"/></Decorator></Decorator>"""


def _line(inlier: str, out: str) -> str:
    return f"""
<Action ID="FitLineSegmentToMask3D" point_cloud="{{point_cloud}}" mask3d="{{mask3d}}" base_frame="world"
  max_distance_from_line_for_inlier="{inlier}" line_segment_poses="{{{out}}}"/>"""


def _automask(score: str, nms: str, area: str) -> str:
    return f"""
<Action ID="GetMasks2DAutomask" grid_size="11" image="{{image}}" mask_count="{{mask_count}}"
  masks2d="{{masks2d}}" score_threshold="{score}" decoder_model_path="models/sam2.1_decoder.onnx"
  encoder_model_path="models/sam2.1_hiera_l_image_encoder.onnx"
  prompt_encoder_model_path="models/sam2.1_prompt_encoder.onnx" nms_threshold="{nms}"
  model_package="factory_sim" min_component_area="{area}"/>
<Action ID="PublishMask2D" masks="{{masks2d}}" masks_visualization_topic="/masks_visualization"
  image="{{image}}" opacity="0.500000"/>"""


OBJECTIVES = {
    "detect_hinge_line_segment": CAMERA
    + _maskrcnn("hinge_masks2d", "10.0", "space booth cabinet hinge")
    + _first("masks3d", "mask3d")
    + _line("0.02", "line_segment_poses"),
    "detect_lever_handle_line_segment": CAMERA
    + _maskrcnn("handle_masks2d", "10.0", "handle")
    + _first("masks3d", "mask3d")
    + _line("0.01", "handle_poses"),
    "detect_fixed_handle_graspable_object": CAMERA
    + _maskrcnn("handle_masks2d", "15.0", "pull handle")
    + _graspable("0.01", "0.000625", "0.02", "handle_objects")
    + _first("handle_objects", "handle_object")
    + """
<Action ID="ExtractGraspableObjectPose" graspable_object="{handle_object}" pose="{grasp_pose}"/>
<Action ID="UnpackGraspableObjectMessage" graspable_object="{handle_object}" object="{collision_object}"
  object_color="{object_color}" grasp_info="{grasp_info}"/>
<Action ID="AddCollisionObject" collision_object="{collision_object}" overwrite="true"/>""",
    "detect_door_graspable_object": CAMERA
    + _maskrcnn("masks2d", "15.0", "{detection_classes}", 'min_relative_area="0.05" max_relative_area="0.8"')
    + _graspable("0.01", "0.000625", "0.02", "door_objects")
    + _first("door_objects", "door_object"),
    "push_button_ml": CAMERA
    + _maskrcnn("masks2d", "15", "button", 'min_relative_area="0" max_relative_area="0.7"')
    + _graspable("0.02", "0.000625", "0.03", "graspable_objects")
    + _first("graspable_objects", "button")
    + """
<Action ID="ExtractGraspableObjectPose" graspable_object="{button}" pose="{button_pose}"/>""",
    "move_boxes_to_loading_zone_from_waypoint": CAMERA
    + """
<Action ID="FilterMasks2DByArea" masks="{masks2d}" min_area="2000" max_area="23000"
  filtered_masks="{masks2d}"/>
<Action ID="GetSizeOfVector" vector_in="{masks2d}" vector_size="{mask_count}"/>"""
    + MASKS_TO_3D.replace("MASKS", "masks2d")
    + _graspable("0.01", "0.0003", "0.2", "graspable_objects", cloud="point_cloud_cropped"),
    "generate_graspable_object": CAMERA
    + MASKS_TO_3D.replace("MASKS", "masks2d")
    + _graspable("0.010000", "0.000625", "0.010000", "graspable_objects"),
    "automask_from_camera": CAMERA + _automask("0.8", "0.200000", "2000"),
    "automask_from_file": CAMERA + _automask("0.500000", "0.3", "200"),
    "automask_camera_iterate_masks": CAMERA + _automask("0.800000", "0.3", "2000"),
    "calibrate_sam3_mask_areas": CAMERA
    + """
<Decorator ID="ForEach" vector_in="{masks2d}" index="{idx}" out="{mask}">
  <Action ID="GetMask2DProperties" mask="{mask}" width="{w}" height="{h}" area="{area}"/>
</Decorator>""",
}


@pytest.fixture(scope="module")
def lab_sim() -> tuple[Any, Any]:
    from kinema.config import ObjectiveLibrary, resolve_config
    from kinema.plugins import BehaviorHost

    resolved = resolve_config("lab_sim")
    host = BehaviorHost.for_config(resolved)
    host.load().raise_for_errors()
    return ObjectiveLibrary.load(resolved), host.registry.create_factory()


@pytest.mark.parametrize("objective", sorted(OBJECTIVES))
def test_the_example_objectives_calls_validate_against_lab_sim(
    lab_sim: tuple[Any, Any], tmp_path: Path, objective: str
) -> None:
    from kinema.runtime.library_check import file_problem

    library, factory = lab_sim
    xml = (
        f'<root BTCPP_format="4" main_tree_to_execute="{objective}"><BehaviorTree ID="{objective}">'
        f'<Control ID="Sequence">{OBJECTIVES[objective]}</Control></BehaviorTree></root>'
    )
    path = tmp_path / f"{objective}.xml"
    path.write_text(xml)
    assert file_problem(library, path, factory) is None
