"""Perception maths on point clouds and camera images, as numpy arrays; no behavior tree, no transport.

* :class:`PointCloud` (``point_cloud.py``) — points (Nx3, m), optional colours, frame id, organised shape;
  ``transformed``, ``centroid``, ``finite``;
* :class:`CameraIntrinsics` (``intrinsics.py``) — a pinhole camera, from a vertical field of view;
* :func:`depth_to_cloud` (``depth.py``) — a depth image → an organised cloud in the optical frame;
* :func:`crop_box`, :func:`remove_box` (``box_filter.py``) — keep / drop the points inside a posed box;
* :func:`voxel_downsample`, :func:`merge_clouds` (``voxel_grid.py``) — one point per occupied voxel;
* :func:`occupied_cells`, :func:`outside_boxes` (``occupancy.py``) — a cloud as occupied grid cubes;
* :func:`register_icp` (``icp.py``) — point-to-point ICP (nearest neighbours with scipy's cKDTree);
* :func:`load_pcd`, :func:`save_pcd` (``pcd.py``) — PCL's .pcd files;
* :func:`sample_mesh_surface` (``mesh_sampling.py``) — points spread evenly over an STL's surface;
* :func:`slice_contour` (``contour.py``) — poses along the outline of a slice of a cloud;
* :func:`surface_normal`, :func:`pose_on_surface` (``surface_pose.py``) — the normal of a neighbourhood
  facing a viewpoint, and a pose on the surface with z along it;
* :func:`fit_line_segment` (``line_fit.py``) — the segment points lie along (RANSAC, then their extent);
* :func:`fit_face_box` (``face_box.py``) — the box of an object from the face a camera sees of it;
* :func:`camera_in_base` (``calibration.py``) — a camera's pose from three tags on a calibration tool;
* ``ros_messages.py`` — the edge: ``sensor_msgs`` PointCloud2 / Image / CameraInfo ↔ the above.

Heavy dependencies (scipy, trimesh) load inside the functions that need them.
"""

from __future__ import annotations

from typing import Any

from kinema.lazy_exports import LazyExports

_EXPORTS = {
    "PointCloud": "point_cloud",
    "CameraIntrinsics": "intrinsics",
    "depth_to_cloud": "depth",
    "crop_box": "box_filter",
    "remove_box": "box_filter",
    "voxel_downsample": "voxel_grid",
    "merge_clouds": "voxel_grid",
    "occupied_cells": "occupancy",
    "outside_boxes": "occupancy",
    "register_icp": "icp",
    "IcpResult": "icp",
    "load_pcd": "pcd",
    "save_pcd": "pcd",
    "sample_mesh_surface": "mesh_sampling",
    "slice_contour": "contour",
    "surface_normal": "surface_pose",
    "pose_on_surface": "surface_pose",
    "fit_line_segment": "line_fit",
    "LineSegment": "line_fit",
    "fit_face_box": "face_box",
    "FaceBox": "face_box",
    "camera_in_base": "calibration",
    "tool_frame_from_tags": "calibration",
}
_lazy = LazyExports(__name__, _EXPORTS)

__all__ = _lazy.names


def __getattr__(name: str) -> Any:
    return _lazy.attribute(name)
