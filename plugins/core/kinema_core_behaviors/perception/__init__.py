"""Perception: camera messages onto the blackboard, AprilTags found in images, point clouds transformed,
cropped, merged, registered, loaded from files, cut out by image masks, read as poses on the surface at
clicked pixels and turned into obstacles (planning scene, collision spheres); masked objects fitted with
boxes and line segments, image masks measured and filtered by area. The segmentation-model behaviors are
known but fail when they run (no model).

Ports hold ``sensor_msgs`` messages as MoveIt Pro's do; the work is done on numpy arrays by
:mod:`kinema.perception`, with the conversions in :mod:`.clouds`.
"""

from __future__ import annotations

from .apriltags import DetectAprilTags, GetDetectionPose
from .bounding_boxes import CreateBoundingBoxFromOffset
from .box_filters import CropPointsInBox, RemovePointsInBox
from .calibrate_camera_pose import CalibrateCameraPose
from .camera_topics import GetCameraInfo, GetImage, GetPointCloud
from .centroid import GetCentroidFromPointCloud
from .collision_spheres import CreateCollisionSpheresAtClosestPoints
from .contour_from_slice import GetContourFromPointCloudSlice
from .find_masked_objects import FindMaskedObjects
from .graspable_objects import ExtractGraspableObjectPose, GetGraspableObjectsFromMasks3D
from .line_segment import FitLineSegmentToMask3D
from .load_point_cloud_from_file import LoadPointCloudFromFile
from .mask_areas import FilterMasks2DByArea, GetMask2DProperties
from .masks import GetMasks3DFromMasks2D, GetPointCloudFromMask3D
from .merge_point_clouds import MergePointClouds
from .pose_from_pixel_coords import GetPoseFromPixelCoords
from .register_point_clouds import RegisterPointClouds
from .segmentation import (
    GetMasks2DAction,
    GetMasks2DAutomask,
    GetMasks2DFromExemplar,
    GetMasks2DFromPointQuery,
)
from .synced_image_and_cloud import GetSyncedImageAndPointCloud
from .transform_point_cloud import TransformPointCloud, TransformPointCloudFrame
from .tray_place_positions import ComputeTrayPlacePositionsUsingAprilTags
from .update_planning_scene import UpdatePlanningSceneService

BEHAVIORS = (
    GetPointCloud,
    GetImage,
    GetCameraInfo,
    TransformPointCloud,
    TransformPointCloudFrame,
    CropPointsInBox,
    RemovePointsInBox,
    GetCentroidFromPointCloud,
    GetPoseFromPixelCoords,
    MergePointClouds,
    RegisterPointClouds,
    LoadPointCloudFromFile,
    UpdatePlanningSceneService,
    GetMasks2DFromExemplar,
    GetMasks2DFromPointQuery,
    GetMasks2DAutomask,
    GetMasks2DAction,
    CreateBoundingBoxFromOffset,
    GetMask2DProperties,
    FilterMasks2DByArea,
    GetMasks3DFromMasks2D,
    GetPointCloudFromMask3D,
    FindMaskedObjects,
    GetGraspableObjectsFromMasks3D,
    ExtractGraspableObjectPose,
    FitLineSegmentToMask3D,
    CreateCollisionSpheresAtClosestPoints,
    DetectAprilTags,
    GetDetectionPose,
    ComputeTrayPlacePositionsUsingAprilTags,
    GetSyncedImageAndPointCloud,
    GetContourFromPointCloudSlice,
    CalibrateCameraPose,
)
