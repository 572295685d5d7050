"""LoadPointCloudFromFile: a cloud from a PCD file, or points sampled on a mesh (STL, OBJ, PLY)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from kinema.behaviors import NodeStatus, PortInfo, SyncBehavior, input_port
from kinema.errors import PerceptionError

from ..files.locations import file_to_read, split_package_uri
from ..messages.ports import (
    fails_on_bad_input,
    message_output,
    port_error,
    read_input,
    read_text,
)
from .clouds import POINT_CLOUD, parse_color, write_cloud

MESH_SUFFIXES = (".stl", ".obj", ".ply", ".off", ".glb", ".gltf")


class LoadPointCloudFromFile(SyncBehavior):
    """Loads ``file_path`` (in ``package_name`` when given) as a cloud labelled ``frame_id``.

    A ``.pcd`` file is read as it is; a mesh (``.stl``, ``.obj``, ``.ply``, ...) becomes
    ``num_sampled_points`` points spread evenly over its surface (``random_seed`` makes that
    reproducible). Coordinates are multiplied by ``scale``; every point gets ``color`` (r;g;b), except
    PCD points that have colours of their own. Fails naming the file and the folders looked in.
    """

    subcategory = "Perception - 3D Point Cloud"

    @classmethod
    def provided_ports(cls) -> list[PortInfo]:
        return [
            input_port("file_path", str, description="The PCD or mesh file (relative to the package)."),
            input_port("package_name", str, "", "The package the path is in ('' : the objectives folder)."),
            input_port("frame_id", str, "world", "The frame the file's coordinates are in."),
            input_port("num_sampled_points", int, 10000, "Points sampled on a mesh's surface."),
            input_port("random_seed", int, 0, "Seed of the mesh sampling (the same seed, the same points)."),
            input_port("scale", float, 1.0, "Factor on the coordinates (0.001 for a mesh in millimetres)."),
            input_port("color", str, "255;255;255", "Colour r;g;b (0-255) given to the points."),
            message_output("point_cloud", POINT_CLOUD, "{point_cloud}", "The cloud."),
        ]

    @fails_on_bad_input
    def tick(self) -> NodeStatus:
        import numpy as np

        from kinema.perception import load_pcd, sample_mesh_surface

        package, text = split_package_uri(str(read_input(self, "file_path")))
        package = read_text(self, "package_name") or package
        path = file_to_read(self, "file_path", text, package)
        frame = str(read_input(self, "frame_id"))
        scale = float(read_input(self, "scale"))
        if not scale > 0:
            raise port_error(self, "scale", f"= {scale}", "give a factor > 0 (1.0 keeps metres)")
        color = parse_color(self, "color", read_input(self, "color"))
        suffix = Path(path).suffix.lower()
        try:
            if suffix == ".pcd":
                cloud = load_pcd(path, frame_id=frame)
                colors = cloud.colors
                if colors is None:
                    colors = np.tile(np.array(color, dtype=np.uint8), (len(cloud), 1))
                cloud = replace(cloud, points=cloud.points * scale, colors=colors)
            elif suffix in MESH_SUFFIXES:
                count = int(read_input(self, "num_sampled_points"))
                if count < 1:
                    raise port_error(self, "num_sampled_points", f"= {count}", "give at least 1")
                cloud = sample_mesh_surface(
                    path, count, scale=scale, seed=self._seed(), frame_id=frame, color=color
                )
            else:
                raise port_error(
                    self,
                    "file_path",
                    f"= {str(path)!r} has an unknown kind of file",
                    f"give a .pcd file or a mesh ({', '.join(MESH_SUFFIXES)})",
                )
        except PerceptionError as error:
            raise port_error(self, "file_path", str(error), "") from None
        write_cloud(self, "point_cloud", cloud)
        return NodeStatus.SUCCESS

    def _seed(self) -> int | None:
        """The seed; an objective passing an unset ``{random_seed}`` gets random sampling."""
        key = self.port_blackboard_key("random_seed")
        if key is not None and getattr(self.config.blackboard.get_entry(key), "value", None) is None:
            return None
        return int(read_input(self, "random_seed"))
