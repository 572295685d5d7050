"""Exporting Kinema's interface packages as ROS 2 packages for colcon."""

from __future__ import annotations

from pathlib import Path

import pytest
from lxml import etree

from kinema.errors import TransportError
from kinema.interfaces import interfaces_dir
from kinema.interfaces.export import export_packages, main


def test_export_writes_buildable_package_layout(tmp_path: Path) -> None:
    (folder,) = export_packages(tmp_path, ["moveit_studio_sdk_msgs"])
    source = interfaces_dir() / "moveit_studio_sdk_msgs"
    srv = folder / "srv" / "ExecuteObjective.srv"
    assert srv.read_text() == (source / "srv" / "ExecuteObjective.srv").read_text()
    manifest = etree.parse(str(folder / "package.xml")).getroot()
    assert manifest.findtext("name") == "moveit_studio_sdk_msgs"
    depends = {element.text for element in manifest.findall("depend")}
    assert {"moveit_msgs", "geometry_msgs", "sensor_msgs", "action_msgs"} <= depends
    assert manifest.findtext("member_of_group") == "rosidl_interface_packages"
    cmake = (folder / "CMakeLists.txt").read_text()
    assert '"action/DoObjectiveSequence.action"' in cmake and "DEPENDENCIES" in cmake


def test_command_line_exports_the_default_packages(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([str(tmp_path)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "kinema_msgs",
        "moveit_studio_agent_msgs",
        "moveit_studio_sdk_msgs",
    ]


def test_unknown_package_names_the_alternatives(tmp_path: Path) -> None:
    with pytest.raises(TransportError, match="did you mean 'kinema_msgs'"):
        export_packages(tmp_path, ["kinema_msg"])
