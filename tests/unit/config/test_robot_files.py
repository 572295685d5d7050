"""kinema.config.robot_files: finding packages, resolving URIs, xacro, checking and converting meshes."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from kinema.config.robot_files import (
    PackageIndex,
    check_mesh,
    convert_mesh,
    converted_mesh_rgba,
    is_ascii_stl,
    process_xacro,
    resolve_robot,
    resolve_uri,
)
from kinema.errors import ConfigError

LFS_POINTER = (
    "version https://git-lfs.github.com/spec/v1\n"
    "oid sha256:4d7a214614ab2935c943f9e0ff69d22eadbb8f32b1258daaa5e2ca24d17e2393\nsize 12345\n"
)


def make_package(folder: Path, name: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "package.xml").write_text(f"<package format='3'><name>{name}</name></package>")
    return folder


def write_cube_stl(path: Path) -> Path:
    import trimesh

    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.creation.box(extents=(0.1, 0.2, 0.3)).export(str(path))
    return path


def bare_index(**kwargs: object) -> PackageIndex:
    """An index that sees only what a test gives it (no environment, no site-packages)."""
    kwargs.setdefault("environ", {})
    kwargs.setdefault("site_packages", [])
    return PackageIndex(**kwargs)  # type: ignore[arg-type]


# -- PackageIndex ----------------------------------------------------------------------------------------


def test_every_source_finds_its_package(tmp_path: Path) -> None:
    explicit = make_package(tmp_path / "ws" / "mine", "mine")
    scanned = make_package(tmp_path / "src" / "deep" / "folder_name_differs", "declared_name")
    ros = make_package(tmp_path / "ros" / "ros_pkg", "ros_pkg")
    named_only = tmp_path / "ros2" / "no_manifest_pkg"
    named_only.mkdir(parents=True)
    ament = tmp_path / "install" / "share" / "ament_pkg"
    ament.mkdir(parents=True)
    cmeel = tmp_path / "site" / "cmeel.prefix" / "share" / "pip-robot-data"
    cmeel.mkdir(parents=True)
    index = PackageIndex(
        packages={"mine": explicit},
        package_roots=[tmp_path / "src"],
        environ={
            "ROS_PACKAGE_PATH": os.pathsep.join([str(tmp_path / "ros"), str(tmp_path / "ros2")]),
            "AMENT_PREFIX_PATH": str(tmp_path / "install"),
        },
        site_packages=[tmp_path / "site"],
    )
    assert index.find("mine") == explicit.resolve()
    assert index.find("declared_name") == scanned.resolve()  # the package.xml's name, not the folder's
    assert index.find("ros_pkg") == ros.resolve()
    assert index.find("no_manifest_pkg") == named_only.resolve()
    assert index.find("ament_pkg") == ament.resolve()
    assert index.find("pip-robot-data") == cmeel.resolve()
    assert index.find("nowhere") is None


def test_the_callers_folders_win_over_the_environment(tmp_path: Path) -> None:
    ours = make_package(tmp_path / "workspace" / "robot_description", "robot_description")
    theirs = make_package(tmp_path / "ros" / "robot_description", "robot_description")
    index = bare_index(
        package_roots=[tmp_path / "workspace"], environ={"ROS_PACKAGE_PATH": str(tmp_path / "ros")}
    )
    assert index.find("robot_description") == ours.resolve()
    assert theirs.resolve() != ours.resolve()


def test_the_not_found_message_lists_where_it_looked_and_near_names(tmp_path: Path) -> None:
    make_package(tmp_path / "src" / "ur_description", "ur_description")
    index = bare_index(package_roots=[tmp_path / "src"], environ={"AMENT_PREFIX_PATH": "/opt/ros/jazzy"})
    message = index.not_found_message("ur_descripton")
    assert str(tmp_path / "src") in message
    assert "/opt/ros/jazzy/share (AMENT_PREFIX_PATH)" in message
    assert "ROS_PACKAGE_PATH (not set)" in message
    assert "did you mean 'ur_description'" in message


def test_the_environments_pip_installed_description_packages_are_found() -> None:
    folder = PackageIndex(environ={}).find("example-robot-data")
    if folder is None:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data)")
    assert (folder / "robots" / "panda_description" / "urdf" / "panda.urdf").is_file()


# -- URIs -----------------------------------------------------------------------------------------------


def test_uris_resolve_to_absolute_paths(tmp_path: Path) -> None:
    package = make_package(tmp_path / "src" / "arm_description", "arm_description")
    index = bare_index(package_roots=[tmp_path / "src"])
    base = tmp_path / "urdf"
    cases = {
        "package://arm_description/meshes/a.stl": package.resolve() / "meshes" / "a.stl",
        "file:///opt/meshes/b%20c.stl": Path("/opt/meshes/b c.stl"),
        "/abs/c.stl": Path("/abs/c.stl"),
        "../meshes/d.stl": (tmp_path / "meshes" / "d.stl").resolve(),
        "e.stl": (base / "e.stl").resolve(),
    }
    for uri, expected in cases.items():
        assert resolve_uri(uri, base_dir=base, index=index) == expected, uri


def test_an_unknown_package_names_the_package_the_uri_and_where_it_looked(tmp_path: Path) -> None:
    index = bare_index(package_roots=[tmp_path])
    from kinema.errors import SourceLocation

    with pytest.raises(ConfigError) as caught:
        resolve_uri(
            "package://missing_pkg/meshes/a.stl",
            base_dir=tmp_path,
            index=index,
            location=SourceLocation("robot.urdf", 12),
        )
    text = str(caught.value)
    assert text.startswith("robot.urdf:12: package://missing_pkg/meshes/a.stl")
    assert "'missing_pkg' not found" in text and str(tmp_path) in text


def test_an_unsupported_scheme_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="only package://, file:// and file paths"):
        resolve_uri("https://example.invalid/a.stl", base_dir=tmp_path, index=bare_index())


# -- xacro ------------------------------------------------------------------------------------------------

XACRO_ROBOT = """<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="prefix" default="left_"/>
  <xacro:include filename="$(find arm_parts)/parts.xacro"/>
  <xacro:link_with_mesh name="$(arg prefix)base" mesh="package://arm_parts/meshes/base.stl"/>
</robot>
"""

XACRO_PARTS = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="link_with_mesh" params="name mesh">
    <link name="${name}">
      <visual><geometry><mesh filename="${mesh}"/></geometry></visual>
    </link>
  </xacro:macro>
</robot>
"""


@pytest.fixture
def xacro_workspace(tmp_path: Path) -> tuple[Path, PackageIndex]:
    parts = make_package(tmp_path / "src" / "arm_parts", "arm_parts")
    (parts / "parts.xacro").write_text(XACRO_PARTS)
    write_cube_stl(parts / "meshes" / "base.stl")
    robot = make_package(tmp_path / "src" / "arm_description", "arm_description")
    (robot / "arm.urdf.xacro").write_text(XACRO_ROBOT)
    return robot / "arm.urdf.xacro", bare_index(package_roots=[tmp_path / "src"])


def test_xacro_expands_with_arguments_and_finds_packages_through_the_index(
    xacro_workspace: tuple[Path, PackageIndex],
) -> None:
    path, index = xacro_workspace
    assert '<link name="left_base">' in process_xacro(path, {}, index=index)
    assert '<link name="right_base">' in process_xacro(path, {"prefix": "right_"}, index=index)


def test_xacro_find_of_an_unknown_package_is_a_config_error(tmp_path: Path) -> None:
    path = tmp_path / "robot.urdf.xacro"
    path.write_text(XACRO_ROBOT)
    with pytest.raises(ConfigError, match="'arm_parts' not found"):
        process_xacro(path, {}, index=bare_index())


def test_a_xacro_syntax_error_names_file_and_line(tmp_path: Path) -> None:
    path = tmp_path / "broken.urdf.xacro"
    path.write_text(
        '<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">\n  <link name="a">\n</robot>\n'
    )
    with pytest.raises(ConfigError) as caught:
        process_xacro(path, {}, index=bare_index())
    assert caught.value.location is not None
    assert caught.value.location.file == str(path) and caught.value.location.line == 3


def test_a_syntax_error_in_an_included_xacro_names_the_included_file(tmp_path: Path) -> None:
    top = tmp_path / "top.urdf.xacro"
    top.write_text(
        '<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:include filename="parts.xacro"/>\n</robot>\n'
    )
    (tmp_path / "parts.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n\n  <link name="a">\n</robot>\n'
    )
    with pytest.raises(ConfigError) as caught:
        process_xacro(top, {}, index=bare_index())
    assert str(caught.value).startswith(f"{tmp_path / 'parts.xacro'}:4: xacro: not valid XML: mismatched tag")


def test_a_xacro_error_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "bad.urdf.xacro"
    path.write_text(
        '<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<link name="${undefined_property}"/></robot>'
    )
    with pytest.raises(
        ConfigError, match=r"xacro failed: name 'undefined_property' is not defined when"
    ) as caught:
        process_xacro(path, {}, index=bare_index())
    assert caught.value.location is not None and caught.value.location.file == str(path)


def test_a_plain_urdf_comes_back_unchanged(tmp_path: Path) -> None:
    text = '<?xml version="1.0"?>\n<robot name="plain">  <link name="base"/>\n</robot>\n'
    path = tmp_path / "plain.urdf"
    path.write_text(text)
    assert process_xacro(path, {"ignored": "1"}) == text


# -- meshes -----------------------------------------------------------------------------------------------


def test_a_missing_mesh_and_an_lfs_pointer_are_told_apart(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="mesh not found"):
        check_mesh(tmp_path / "nothing.stl")
    pointer = tmp_path / "base.stl"
    pointer.write_text(LFS_POINTER)
    with pytest.raises(ConfigError) as caught:
        check_mesh(pointer)
    assert f"mesh {pointer} is a Git LFS pointer file (run `git lfs pull`)" in str(caught.value)
    real = write_cube_stl(tmp_path / "real.stl")
    assert check_mesh(real) == real


def test_stl_and_obj_pass_through_unconverted(tmp_path: Path) -> None:
    stl = write_cube_stl(tmp_path / "a.stl")
    assert convert_mesh(stl, tmp_path / "cache") == stl
    assert not (tmp_path / "cache").exists()


def test_a_text_stl_is_converted_because_mujoco_reads_only_binary_stl(tmp_path: Path) -> None:
    import mujoco
    import trimesh

    text = tmp_path / "cube.stl"
    text.write_bytes(trimesh.creation.box(extents=(0.1, 0.2, 0.3)).export(file_type="stl_ascii").encode())
    binary = write_cube_stl(tmp_path / "binary.stl")
    labelled = tmp_path / "solid_header.stl"  # a binary STL whose 80-byte header starts with "solid"
    labelled.write_bytes(b"solid exported by a CAD tool".ljust(80, b" ") + binary.read_bytes()[80:])
    assert [is_ascii_stl(p) for p in (text, binary, labelled)] == [True, False, False]
    assert convert_mesh(labelled, tmp_path / "cache") == labelled
    converted = convert_mesh(text, tmp_path / "cache")
    assert converted.suffix == ".obj" and converted.parent == tmp_path / "cache"
    model = mujoco.MjModel.from_xml_string(
        f'<mujoco><asset><mesh name="m" file="{converted}"/></asset>'
        '<worldbody><geom type="mesh" mesh="m"/></worldbody></mujoco>'
    )
    assert model.mesh_vertnum[0] >= 8


COLLADA_TETRAHEDRON = """<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit meter="1" name="meter"/><up_axis>Z_UP</up_axis></asset>
  <library_effects>
    <effect id="red-fx"><profile_COMMON><technique sid="common"><phong>
      <diffuse><color>{red} 0.1 0.1 1</color></diffuse>
    </phong></technique></profile_COMMON></effect>
  </library_effects>
  <library_materials>
    <material id="red" name="red"><instance_effect url="#red-fx"/></material>
  </library_materials>
  <library_geometries>
    <geometry id="tetra" name="tetra"><mesh>
      <source id="tetra-pos">
        <float_array id="tetra-pos-array" count="12">0 0 0 0.1 0 0 0 0.2 0 0 0 0.3</float_array>
        <technique_common><accessor source="#tetra-pos-array" count="4" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common>
      </source>
      <vertices id="tetra-vtx"><input semantic="POSITION" source="#tetra-pos"/></vertices>
      <triangles material="mat" count="4">
        <input semantic="VERTEX" source="#tetra-vtx" offset="0"/>
        <p>0 2 1 0 1 3 0 3 2 1 2 3</p>
      </triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="scene"><node id="part" name="part">
      <translate>0 0 0.5</translate>
      <instance_geometry url="#tetra"><bind_material><technique_common>
        <instance_material symbol="mat" target="#red"/>
      </technique_common></bind_material></instance_geometry>
    </node></visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
"""


def test_a_collada_mesh_becomes_an_obj_once_with_its_colour(tmp_path: Path) -> None:
    import trimesh

    pytest.importorskip("collada", reason="pycollada is not installed")
    dae = tmp_path / "part.dae"
    dae.write_text(COLLADA_TETRAHEDRON.format(red=0.8))
    cache = tmp_path / "cache"

    converted = convert_mesh(dae, cache)
    assert converted.suffix == ".obj" and converted.parent == cache
    reloaded = trimesh.load(str(converted), force="mesh")
    # The node's translation is applied: the OBJ is in the DAE file's frame.
    assert reloaded.bounds.flatten().tolist() == pytest.approx([0, 0, 0.5, 0.1, 0.2, 0.8], abs=1e-6)
    assert len(reloaded.faces) == 4
    rgba = converted_mesh_rgba(converted)
    assert rgba == pytest.approx((0.8, 0.1, 0.1, 1.0), abs=0.01)

    stamp = converted.stat().st_mtime_ns
    assert convert_mesh(dae, cache) == converted
    assert converted.stat().st_mtime_ns == stamp  # cached: not written again

    dae.write_text(COLLADA_TETRAHEDRON.format(red=0.5))
    assert convert_mesh(dae, cache) != converted  # new content, new file


# -- resolve_robot ---------------------------------------------------------------------------------------

ROBOT = """<?xml version="1.0"?>
<robot name="two_link">
  <link name="base">
    <visual><geometry><mesh filename="package://two_link_description/meshes/base.stl"/></geometry></visual>
    <collision><geometry><mesh filename="../meshes/base.stl"/></geometry></collision>
  </link>
  <link name="arm">
    <collision><geometry><mesh filename="{arm_mesh}"/></geometry></collision>
  </link>
  <link name="finger"/>
  <link name="finger2"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="arm"/><limit lower="-1" upper="1" effort="10" velocity="1"/>
  </joint>
  <joint name="grip" type="prismatic">
    <parent link="arm"/><child link="finger"/><limit lower="0" upper="0.04" effort="10" velocity="1"/>
  </joint>
  <joint name="grip_mimic" type="prismatic">
    <parent link="arm"/><child link="finger2"/><limit lower="0" upper="0.04" effort="10" velocity="1"/>
    <mimic joint="grip" multiplier="1"/>
  </joint>
</robot>
"""


def two_link(
    tmp_path: Path, arm_mesh: str = "package://two_link_description/meshes/arm.stl"
) -> tuple[Path, PackageIndex]:
    package = make_package(tmp_path / "src" / "two_link_description", "two_link_description")
    write_cube_stl(package / "meshes" / "base.stl")
    write_cube_stl(package / "meshes" / "arm.stl")
    urdf = package / "urdf" / "robot.urdf"
    urdf.parent.mkdir()
    urdf.write_text(ROBOT.format(arm_mesh=arm_mesh))
    return urdf, bare_index(package_roots=[tmp_path / "src"])


def test_a_robot_resolves_every_mesh_with_its_line(tmp_path: Path) -> None:
    urdf, index = two_link(tmp_path)
    robot = resolve_robot(urdf, index=index)
    package = index.find("two_link_description")
    assert package is not None
    assert robot.name == "two_link"
    assert [(m.link, m.role, m.path, m.location.line) for m in robot.meshes] == [
        ("base", "visual", package / "meshes" / "base.stl", 4),
        ("base", "collision", package / "meshes" / "base.stl", 5),
        ("arm", "collision", package / "meshes" / "arm.stl", 8),
    ]
    assert robot.movable_joints() == ["shoulder", "grip", "grip_mimic"]
    assert robot.root_link() == "base"


def test_the_written_urdf_has_absolute_mesh_paths_and_loads_in_pinocchio(tmp_path: Path) -> None:
    import pinocchio as pin

    urdf, index = two_link(tmp_path)
    robot = resolve_robot(urdf, index=index)
    copy = robot.write_urdf(tmp_path / "out" / "robot.urdf")
    text = copy.read_text()
    assert "package://" not in text and "../meshes" not in text
    model = pin.buildModelFromUrdf(str(copy))
    geometry = pin.buildGeomFromUrdf(model, str(copy), pin.GeometryType.COLLISION)
    assert sorted(Path(g.meshPath).name for g in geometry.geometryObjects) == ["arm.stl", "base.stl"]


@pytest.mark.parametrize(
    ("arm_mesh", "message"),
    [
        (
            "package://nope/arm.stl",
            "link 'arm' (collision): package://nope/arm.stl: ROS package 'nope' not found",
        ),
        ("package://two_link_description/meshes/gone.stl", "link 'arm' (collision): mesh not found"),
        ("package://two_link_description/meshes/lfs.stl", "is a Git LFS pointer file (run `git lfs pull`)"),
    ],
)
def test_a_bad_mesh_is_reported_at_its_line(tmp_path: Path, arm_mesh: str, message: str) -> None:
    urdf, index = two_link(tmp_path, arm_mesh)
    (urdf.parent.parent / "meshes" / "lfs.stl").write_text(LFS_POINTER)
    with pytest.raises(ConfigError) as caught:
        resolve_robot(urdf, index=index)
    assert message in str(caught.value)
    assert str(caught.value).startswith(f"{urdf}:8: ")


def test_a_file_that_is_not_a_urdf_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "scene.urdf"
    path.write_text("<mujoco/>")
    with pytest.raises(ConfigError, match="not a URDF"):
        resolve_robot(path, index=bare_index())


def test_a_xacro_robot_resolves_its_meshes(xacro_workspace: tuple[Path, PackageIndex]) -> None:
    path, index = xacro_workspace
    robot = resolve_robot(path, xacro_args={"prefix": "r_"}, index=index)
    assert [m.link for m in robot.meshes] == ["r_base"]
    assert robot.meshes[0].path.is_file()


# -- pinocchio and example-robot-data ------------------------------------------------------------------


def test_pinocchio_resolves_example_robot_data_uris_through_package_dirs(tmp_path: Path) -> None:
    import pinocchio as pin

    index = PackageIndex(environ={})
    share = index.find("example-robot-data")
    if share is None:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data)")
    urdf = share / "robots" / "panda_description" / "urdf" / "panda.urdf"
    model = pin.buildModelFromUrdf(str(urdf))
    with pytest.raises(ValueError, match="could not be found"):  # pinocchio has no lookup of its own
        pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION, package_dirs=[str(tmp_path)])
    geometry = pin.buildGeomFromUrdf(
        model, str(urdf), pin.GeometryType.COLLISION, package_dirs=[str(p) for p in index.package_dirs()]
    )
    meshes = [Path(g.meshPath) for g in geometry.geometryObjects if g.meshPath.endswith(".stl")]
    assert meshes and all(m.is_file() for m in meshes)
    robot = resolve_robot(urdf, index=index)
    assert {m.path for m in robot.meshes if m.role == "collision"} == set(meshes)


def test_every_unusable_mesh_is_reported_at_once(tmp_path: Path) -> None:
    urdf, _ = two_link(tmp_path, "package://two_link_description/meshes/gone.stl")
    text = urdf.read_text()
    text = text.replace(
        "package://two_link_description/meshes/base.stl", "package://ur_descripton/meshes/base.stl"
    )
    text = text.replace("../meshes/base.stl", "package://ur_descripton/meshes/base_collision.stl")
    urdf.write_text(text)
    make_package(tmp_path / "src" / "ur_description", "ur_description")
    with pytest.raises(ConfigError) as caught:
        resolve_robot(urdf, index=bare_index(package_roots=[tmp_path / "src"]))
    lines = str(caught.value).splitlines()
    assert lines[0] == f"{urdf}:8: 3 meshes of the robot cannot be used:"
    assert lines[1].startswith(f"  {urdf}:8: link 'arm' (collision): mesh not found")
    assert lines[2].startswith("  ROS package 'ur_descripton' not found, needed by 2 mesh(es), first ")
    assert f"at {urdf}:4; did you mean 'ur_description'" in lines[2]
    assert lines[3].startswith("  packages were looked for in: ")


# -- a real MoveIt Pro description ------------------------------------------------------------------------

MOVEIT_PRO_PACKAGES = (
    Path(__file__).resolve().parents[4] / "shared" / "compat" / "moveit_pro" / "packages" / "src"
)


def test_a_moveit_pro_xacro_expands_with_its_config_arguments_and_names_what_is_missing() -> None:
    """lab_sim's picknik_ur.xacro: $(find) through the index, urdf_params as arguments, no ROS install."""
    xacro_file = MOVEIT_PRO_PACKAGES / "lab_sim" / "description" / "picknik_ur.xacro"
    if not xacro_file.is_file():
        pytest.skip(f"the MoveIt Pro reference packages are not at {MOVEIT_PRO_PACKAGES}")
    index = bare_index(package_roots=[MOVEIT_PRO_PACKAGES])
    with pytest.raises(ConfigError, match=r"Undefined substitution argument mujoco_viewer"):
        process_xacro(xacro_file, {}, index=index)
    urdf = process_xacro(
        xacro_file,
        {"mujoco_keyframe": "default", "mujoco_model": "description/scene.xml", "mujoco_viewer": "false"},
        index=index,
    )
    assert 'name="shoulder_pan_joint"' in urdf and "package://robotiq_description/" in urdf
    with pytest.raises(ConfigError) as caught:
        resolve_robot(
            xacro_file,
            xacro_args={
                "mujoco_keyframe": "default",
                "mujoco_model": "description/scene.xml",
                "mujoco_viewer": "false",
            },
            index=index,
        )
    message = str(caught.value)
    # The UR and Robotiq description packages are not in the reference tree: one line each, not 40.
    assert "ROS package 'ur_description' not found" in message
    assert "ROS package 'robotiq_description' not found" in message
    assert message.count("ROS package 'ur_description' not found") == 1
