"""SavePoseForUrdf: write a calibrated pose as the ``<origin>`` of a URDF joint (a camera's mount, say)."""

from __future__ import annotations

import datetime

from kinema.behaviors import AsyncBehavior, PortInfo, input_port
from kinema.errors import KinemaError

from ..messages.conversions import POSE_STAMPED_TYPE, pose_matrix
from ..messages.ports import fails_on_bad_input, message_input, port_error, read_input, read_message
from .locations import RELATIVE_WRITE, file_to_write


def urdf_origin(matrix: object) -> str:
    """``<origin xyz="..." rpy="..."/>`` of a 4x4 pose (URDF's fixed-axis roll, pitch, yaw), 9 decimals."""
    import numpy as np

    from kinema.transforms import euler_from_rotation

    pose = np.asarray(matrix, dtype=float)
    xyz = " ".join(f"{v:.9g}" for v in pose[:3, 3])
    rpy = " ".join(f"{v:.9g}" for v in euler_from_rotation(pose))
    return f'<origin xyz="{xyz}" rpy="{rpy}"/>'


class SavePoseForUrdf(AsyncBehavior):
    """Writes ``calibration_pose_stamped`` to the text file ``file_name`` as a URDF joint origin, ready to
    paste into the joint that places the calibrated part (its parent link is the pose's frame)::

        <!-- parent link: world; saved by SavePoseForUrdf 2026-05-01 12:00:00 -->
        <origin xyz="0.5 0.1 1.2" rpy="0 0.7 3.14"/>

    Relative names are in the config's objectives folder; an existing file is replaced (atomically). The
    file's layout in MoveIt Pro is not public; this is Kinema's.
    """

    subcategory = "File Management"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            message_input(
                "calibration_pose_stamped",
                POSE_STAMPED_TYPE,
                "{calibration_pose_stamped}",
                "The pose to save, in the joint's parent link.",
            ),
            input_port("file_name", str, "", f"The file to write; {RELATIVE_WRITE}."),
        ]

    @fails_on_bad_input
    def do_work(self) -> bool:
        from kinema.config.atomic_write import atomic_write_text

        try:
            frame, matrix = pose_matrix(
                read_message(self, "calibration_pose_stamped"), "calibration_pose_stamped"
            )
        except KinemaError as error:
            raise port_error(self, "calibration_pose_stamped", str(error)) from None
        text = str(read_input(self, "file_name")) if "file_name" in self.config.input_ports else ""
        path = file_to_write(self, "file_name", text)
        stamp = datetime.datetime.now().strftime("%Y-%m-%d %H:%M:%S")
        comment = f"<!-- parent link: {frame or 'world'}; saved by SavePoseForUrdf {stamp} -->"
        content = f"{comment}\n{urdf_origin(matrix)}\n"
        try:
            atomic_write_text(path, content)
        except KinemaError as error:
            raise port_error(self, "file_name", f"= {text!r}: {error}", "") from None
        self.logger.publish_info(f"SavePoseForUrdf: wrote {path}")
        return True
