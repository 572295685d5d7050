"""MESH_RESOURCE markers (what VisualizeMesh publishes) are drawn from the mesh file."""

from __future__ import annotations

from pathlib import Path

import meshcat.geometry as g
import numpy as np

from kinema.transport import from_dict
from kinema.viz.markers import MarkerBoard, marker_shapes

STL = """solid tri
facet normal 0 0 1
 outer loop
  vertex 0 0 0
  vertex 1 0 0
  vertex 0 1 0
 endloop
endfacet
endsolid tri
"""


def _mesh_marker(uri: str) -> object:
    return from_dict(
        "visualization_msgs/msg/Marker",
        {
            "ns": "gripper",
            "type": 10,
            "pose": {"position": {"x": 0.5}, "orientation": {"w": 1.0}},
            "scale": {"x": 2.0, "y": 2.0, "z": 2.0},
            "color": {"r": 1.0, "a": 1.0},
            "mesh_resource": uri,
        },
    )


def test_a_file_mesh_is_drawn_where_the_marker_says(tmp_path: Path) -> None:
    mesh = tmp_path / "token.stl"
    mesh.write_text(STL)
    shapes = marker_shapes(_mesh_marker(mesh.as_uri()), np.eye(4))
    assert len(shapes) == 1
    geometry = shapes[0].obj.geometry
    assert isinstance(geometry, g.MeshGeometry) and geometry.mesh_format == "stl"
    assert np.allclose(shapes[0].transform[:3, 3], [0.5, 0.0, 0.0])
    assert np.allclose(np.diag(shapes[0].transform)[:3], [2.0, 2.0, 2.0])
    commands = MarkerBoard().update(_mesh_marker(mesh.as_uri()), np.eye(4))
    assert commands, "the board draws the mesh"


def test_missing_files_and_package_uris_draw_nothing(tmp_path: Path) -> None:
    assert marker_shapes(_mesh_marker((tmp_path / "gone.stl").as_uri()), np.eye(4)) == []
    assert marker_shapes(_mesh_marker("package://lab_sim/meshes/x.stl"), np.eye(4)) == []
