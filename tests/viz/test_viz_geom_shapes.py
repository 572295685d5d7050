"""MuJoCo geoms → meshcat objects: type, size, color and placement, without a browser."""

from __future__ import annotations

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from kinema.viz.geom_shapes import geom_visuals, rgb_to_int  # noqa: E402

SCENE = """
<mujoco>
  <asset>
    <texture name="grid" type="2d" builtin="checker" rgb1="1 1 1" rgb2="0 0 0" width="8" height="8"/>
    <material name="floor" texture="grid" texrepeat="3 3"/>
    <material name="blue" rgba="0 0 1 1"/>
    <mesh name="tetra" vertex="0 0 0  1 0 0  0 1 0  0 0 1"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="2 3 0.1" material="floor"/>
    <geom name="box" type="box" size="0.1 0.2 0.3" pos="1 2 3" rgba="1 0 0 1"/>
    <geom name="ball" type="sphere" size="0.25" rgba="0 1 0 0.5"/>
    <geom name="egg" type="ellipsoid" size="0.1 0.2 0.3" material="blue"/>
    <geom name="can" type="cylinder" size="0.05 0.4"/>
    <geom name="pill" type="capsule" size="0.03 0.2" rgba="1 1 0 1"/>
    <geom name="hidden" type="box" size="0.1 0.1 0.1" group="3"/>
    <geom name="clear" type="box" size="0.1 0.1 0.1" rgba="1 1 1 0"/>
    <body name="arm" pos="0 0 1">
      <joint type="hinge"/>
      <geom name="tetra" type="mesh" mesh="tetra" rgba="0.2 0.4 0.6 1"/>
    </body>
  </worldbody>
</mujoco>
"""

# geom name -> (meshcat geometry types of its parts, key sizes of the first part, rgba drawn)
EXPECTED = {
    "floor": (["BoxGeometry"], {"width": 4.0, "height": 6.0}, (1.0, 1.0, 1.0, 1.0)),
    "box": (["BoxGeometry"], {"width": 0.2, "height": 0.4, "depth": 0.6}, (1.0, 0.0, 0.0, 1.0)),
    "ball": (["SphereGeometry"], {"radius": 0.25}, (0.0, 1.0, 0.0, 0.5)),
    "egg": (["SphereGeometry"], {"radius": 1.0}, (0.0, 0.0, 1.0, 1.0)),
    "can": (["CylinderGeometry"], {"height": 0.8, "radiusTop": 0.05}, (0.5, 0.5, 0.5, 1.0)),
    "pill": (
        ["CylinderGeometry", "SphereGeometry", "SphereGeometry"],
        {"height": 0.4, "radiusTop": 0.03},
        (1.0, 1.0, 0.0, 1.0),
    ),
    "tetra": (["BufferGeometry"], {}, (0.2, 0.4, 0.6, 1.0)),
}


@pytest.fixture(scope="module")
def visuals() -> dict[str, object]:
    model = mujoco.MjModel.from_xml_string(SCENE)
    return {v.name: v for v in geom_visuals(model)}


def test_only_visible_geoms_are_drawn(visuals: dict[str, object]) -> None:
    assert set(visuals) == set(EXPECTED)  # group 3 and alpha 0 are hidden, as in MuJoCo's viewer


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_geom_type_size_and_color(visuals: dict[str, object], name: str) -> None:
    types, sizes, rgba = EXPECTED[name]
    visual = visuals[name]
    lowered = [part.geometry.lower({}) for part in visual.parts]
    assert [item["type"] for item in lowered] == types
    for key, value in sizes.items():
        assert lowered[0][key] == pytest.approx(value)
    assert visual.rgba == pytest.approx(rgba, abs=1e-6)
    material = visual.material().lower({})
    assert material["color"] == rgb_to_int(*rgba[:3])
    assert material["transparent"] == (rgba[3] < 1.0)


def test_geom_pose_is_kept_in_the_body_frame(visuals: dict[str, object]) -> None:
    assert np.allclose(visuals["box"].transform[:3, 3], [1, 2, 3])


def test_cylinders_are_turned_from_meshcat_y_to_mujoco_z(visuals: dict[str, object]) -> None:
    turn = visuals["can"].parts[0].transform
    assert np.allclose(turn[:3, :3] @ [0, 1, 0], [0, 0, 1])
    caps = [part.transform[2, 3] for part in visuals["pill"].parts[1:]]
    assert sorted(caps) == pytest.approx([-0.2, 0.2])


def test_ellipsoid_radii_scale_a_unit_sphere(visuals: dict[str, object]) -> None:
    assert np.allclose(np.diag(visuals["egg"].parts[0].geometry.intrinsic_transform())[:3], [0.1, 0.2, 0.3])


def test_mesh_triangles_come_from_the_model(visuals: dict[str, object]) -> None:
    geometry = visuals["tetra"].parts[0].geometry
    assert geometry.positions.shape[1] == 3
    assert len(geometry.positions) % 3 == 0 and len(geometry.positions) >= 12  # 4 faces of 3 corners
    assert geometry.normals.shape == geometry.positions.shape


def test_textured_floor_carries_its_checker_png(visuals: dict[str, object]) -> None:
    floor = visuals["floor"]
    assert floor.texture_png is not None and floor.texture_png.startswith(b"\x89PNG")
    assert floor.texture_repeat == (3.0, 3.0)
