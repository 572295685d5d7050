"""UI: behaviors that show things to the user and ask them (toasts and TUI notices, ``kinema view`` markers,
point cloud snapshots, 2D detection images, approvals and breakpoints, values only the user can give)."""

from __future__ import annotations

from .approval import BreakpointSubscriber, IsUserAvailable, WaitForMTCSolutionApproval
from .images_2d import PublishBoundingBoxes2D, PublishMask2D
from .log_message import LogMessage
from .markers import PublishMarkers, VisualizeMesh
from .notices import SwitchUIPrimaryView
from .point_clouds import ClearSnapshot, PublishPointCloud, SendPointCloudToUI
from .user_input import (
    DoTeleoperateAction,
    GetPointsFromUser,
    RetrievePoseParameter,
    RetrieveRobotStateParameter,
)
from .visualize_path import VisualizePath
from .visualize_pose import VisualizePose

BEHAVIORS = (
    LogMessage,
    VisualizePose,
    VisualizePath,
    PublishMarkers,
    VisualizeMesh,
    SendPointCloudToUI,
    PublishPointCloud,
    ClearSnapshot,
    PublishMask2D,
    PublishBoundingBoxes2D,
    SwitchUIPrimaryView,
    IsUserAvailable,
    WaitForMTCSolutionApproval,
    BreakpointSubscriber,
    RetrievePoseParameter,
    RetrieveRobotStateParameter,
    GetPointsFromUser,
    DoTeleoperateAction,
)
