"""Saving waypoints never writes into a parent or bundled package; a crash mid-save leaves no temp file."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from kinema.config import Waypoint, WaypointStore, Workspace, resolve_config
from kinema.config.waypoint_location import waypoint_store_for
from kinema.resources import bundled_dir

LAB_SIM_WAYPOINTS = bundled_dir("configs") / "lab_sim" / "waypoints" / "lab_sim_waypoints.yaml"


@pytest.fixture(autouse=True)
def data_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    return tmp_path / "data"


def _names(path: Path) -> list[str]:
    return [item["name"] for item in yaml.safe_load(path.read_text())]


def test_a_config_based_on_lab_sim_saves_into_its_own_package(ws) -> None:  # type: ignore[no-untyped-def]
    package = ws.child("my_cell", "lab_sim")
    shipped = LAB_SIM_WAYPOINTS.read_bytes()
    store = waypoint_store_for(resolve_config("my_cell", Workspace.discover(ws.root)))
    assert store is not None
    inherited = store.names()
    assert inherited == _names(LAB_SIM_WAYPOINTS)  # reads the parent's until something changes

    store.save(Waypoint("Over the Tray", ["linear_rail_joint"], [0.25]))
    store.rename(inherited[0], "Renamed Here")

    assert LAB_SIM_WAYPOINTS.read_bytes() == shipped
    copy = package / "waypoints" / "lab_sim_waypoints.yaml"
    assert store.path == copy
    assert _names(copy) == ["Renamed Here", *inherited[1:], "Over the Tray"]
    assert "takes its waypoints from package 'lab_sim'" in store.notice and str(copy) in store.notice


def test_a_bundled_config_saves_into_the_user_data_folder(data_home: Path) -> None:
    shipped = LAB_SIM_WAYPOINTS.read_bytes()
    for config in ("example_config", "lab_sim"):
        store = waypoint_store_for(resolve_config(config, Workspace.bundled_only()))
        assert store is not None
        store.save(Waypoint(f"Saved in {config}", ["linear_rail_joint"], [0.1]))
        target = data_home / "kinema" / "waypoints" / config / "lab_sim_waypoints.yaml"
        assert store.path == target and _names(target)[-1] == f"Saved in {config}"
        assert "bundled with Kinema" in store.notice and str(target) in store.notice
    assert LAB_SIM_WAYPOINTS.read_bytes() == shipped


def test_a_workspace_config_with_its_own_file_saves_in_place(ws) -> None:  # type: ignore[no-untyped-def]
    package = ws.config("own_cell")
    store = waypoint_store_for(resolve_config("own_cell", Workspace.discover(ws.root)))
    assert store is not None
    store.save(Waypoint("Home", ["j"], [0.0]))
    assert store.path == package / "waypoints" / "waypoints.yaml" and store.notice == ""
    assert _names(store.path) == ["Home"]


KILLED_MID_SAVE = """
import os, signal, sys
from kinema.config import Waypoint, WaypointStore

def die(*_args):  # the temporary file is written and synced; the rename never happens
    os.kill(os.getpid(), signal.SIGKILL)

os.replace = die
WaypointStore(sys.argv[1]).save(Waypoint("Half", ["j"], [1.0]))
"""


def test_a_save_killed_mid_way_leaves_no_temporary_file_behind(tmp_path: Path) -> None:
    path = tmp_path / "waypoints.yaml"
    WaypointStore(path).save(Waypoint("Kept", ["j"], [0.0]))
    killed = subprocess.run(
        [sys.executable, "-c", KILLED_MID_SAVE, str(path)], capture_output=True, timeout=60
    )
    assert killed.returncode == -9, killed.stderr.decode()
    strays = [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
    assert len(strays) == 1, sorted(p.name for p in tmp_path.iterdir())  # what the crash left

    store = WaypointStore(path)
    assert store.names() == ["Kept"]  # readers never see the half-done save
    assert [p.name for p in store.remove_stray_temporaries()] == strays  # what the agent does at start
    assert sorted(p.name for p in tmp_path.iterdir()) == ["waypoints.yaml", "waypoints.yaml.lock"]

    subprocess.run([sys.executable, "-c", KILLED_MID_SAVE, str(path)], capture_output=True, timeout=60)
    store.save(Waypoint("Next", ["j"], [2.0]))  # the next save tidies up too
    assert sorted(p.name for p in tmp_path.iterdir()) == ["waypoints.yaml", "waypoints.yaml.lock"]
    assert store.names() == ["Kept", "Next"]
