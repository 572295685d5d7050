"""Fixtures for config tests: an isolated user config dir and a builder of throw-away workspaces."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml


@pytest.fixture(autouse=True)
def isolated_selection(
    tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch
) -> Iterator[Path]:
    """Keep `kinema configure` state and the KINEMA_* variables of the developer out of every test."""
    home = tmp_path_factory.mktemp("xdg")
    monkeypatch.setenv("XDG_CONFIG_HOME", str(home))
    monkeypatch.delenv("KINEMA_WORKSPACE", raising=False)
    monkeypatch.delenv("KINEMA_CONFIG", raising=False)
    yield home


def root_config(name: str) -> dict[str, Any]:
    """A complete config.yaml for a root package whose files :class:`WorkspaceBuilder` creates."""
    return {
        "hardware": {
            "robot_description": {
                "urdf": {"package": name, "path": "description/robot.urdf"},
                "srdf": {"package": name, "path": "description/robot.srdf"},
            }
        },
        "moveit_params": {"joint_group_name": "manipulator"},
        "objectives": {
            "behavior_loader_plugins": {"core": ["kinema::CoreBehaviorsLoader"]},
            "objective_library_paths": {
                f"{name}_objectives": {"package_name": name, "relative_path": "objectives"}
            },
            "waypoints_file": {"package_name": name, "relative_path": "waypoints/waypoints.yaml"},
        },
    }


class WorkspaceBuilder:
    """Writes packages into ``<root>/src`` for one test."""

    def __init__(self, root: Path) -> None:
        self.root = root
        (root / "src").mkdir(parents=True, exist_ok=True)

    @staticmethod
    def root_data(name: str) -> dict[str, Any]:
        """A complete root config.yaml for package ``name`` (see :func:`root_config`)."""
        return root_config(name)

    def config(
        self, name: str, data: dict[str, Any] | str | None = None, *, folder: str | None = None
    ) -> Path:
        """Create config package ``name`` (default: a complete root config) and return its folder."""
        package = self.root / "src" / (folder or name)
        (package / "config").mkdir(parents=True, exist_ok=True)
        for sub in ("description", "objectives", "waypoints"):
            (package / sub).mkdir(exist_ok=True)
        (package / "description" / "robot.urdf").write_text("<robot name='r'/>\n")
        (package / "description" / "robot.srdf").write_text("<robot name='r'/>\n")
        (package / "waypoints" / "waypoints.yaml").write_text("[]\n")
        if data is None:
            data = root_config(name)
        text = data if isinstance(data, str) else yaml.safe_dump(data, sort_keys=False)
        (package / "config" / "config.yaml").write_text(text)
        return package

    def child(
        self, name: str, parent: str, extra: dict[str, Any] | None = None, *, own_library: bool = True
    ) -> Path:
        """Create a config based on ``parent`` with its own objective library."""
        data: dict[str, Any] = {"based_on_package": parent}
        if own_library:
            data["objectives"] = {
                "objective_library_paths": {
                    f"{name}_objectives": {"package_name": name, "relative_path": "objectives"}
                }
            }
        for key, value in (extra or {}).items():
            if key == "objectives" and "objectives" in data:
                data["objectives"].update(value)
            else:
                data[key] = value
        return self.config(name, data)

    def objective(
        self, package: str, objective_id: str, *, file: str | None = None, body: str = "", **attrs: str
    ) -> Path:
        """Write a minimal objective into ``package``'s objectives/ folder."""
        extra = "".join(f' {key}="{value}"' for key, value in attrs.items())
        text = (
            '<?xml version="1.0" encoding="UTF-8" ?>\n'
            f'<root BTCPP_format="4" main_tree_to_execute="{objective_id}">\n'
            f'  <BehaviorTree ID="{objective_id}"{extra}>\n'
            "    <AlwaysSuccess/>\n"
            "  </BehaviorTree>\n"
            f"{body}"
            "</root>\n"
        )
        path = (
            self.root
            / "src"
            / package
            / "objectives"
            / (file or objective_id.lower().replace(" ", "_") + ".xml")
        )
        path.write_text(text)
        return path


@pytest.fixture
def ws(tmp_path: Path) -> WorkspaceBuilder:
    """A fresh workspace under tmp_path/ws."""
    return WorkspaceBuilder(tmp_path / "ws")
