from __future__ import annotations

import difflib
import shutil
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from kinema.config import Waypoint, WaypointStore
from kinema.errors import ConfigError

JOINTS = ["linear_rail_joint", "shoulder_pan_joint"]


def _waypoint(name: str, *positions: float) -> Waypoint:
    return Waypoint(
        name=name,
        joint_names=list(JOINTS),
        positions=list(positions or (0.0, 0.0)),
        joint_group_names=["manipulator"],
    )


@pytest.fixture
def compat_store(shared_dir: Path, tmp_path: Path) -> WaypointStore:
    path = tmp_path / "ur_waypoints.yaml"
    shutil.copy(shared_dir / "compat" / "moveit_pro" / "config" / "lab_sim_ur_waypoints.yaml", path)
    return WaypointStore(path)


def test_moveit_pro_waypoints_file_parses(compat_store: WaypointStore):
    names = compat_store.names()
    assert len(names) == 28
    assert {"Home", "Look at Table", "3 Waypoint Pick Pose", "Park Far Right"} <= set(names)
    home = compat_store.get("Home")
    assert home.joint_names[:2] == ["robotiq_85_left_knuckle_joint", "linear_rail_joint"]
    assert len(home.positions) == 8
    assert home.joint_group_names == ["gripper", "linear_actuator", "manipulator"]
    assert home.favorite is True
    assert home.joint_positions()["linear_rail_joint"] == pytest.approx(0.20879448072947002)


def test_rewriting_a_moveit_pro_file_keeps_it_byte_identical(shared_dir: Path, compat_store: WaypointStore):
    compat_store.save(compat_store.get("Home"))
    original = (shared_dir / "compat" / "moveit_pro" / "config" / "lab_sim_ur_waypoints.yaml").read_text()
    assert compat_store.path.read_text() == original


def test_get_save_rename_erase(tmp_path: Path):
    store = WaypointStore(tmp_path / "w" / "waypoints.yaml")
    assert store.names() == []
    store.save(_waypoint("A", 0.1, 0.2))
    store.save(_waypoint("B"))
    store.save(_waypoint("A", 0.3, 0.4))  # replaces in place
    assert store.names() == ["A", "B"]
    assert store.get("A").positions == [0.3, 0.4]
    store.rename("A", "C")
    assert store.names() == ["C", "B"]
    store.erase("B")
    assert store.names() == ["C"]
    # the file is MoveIt Pro's shape
    text = store.path.read_text()
    assert "multi_dof_joint_state:" in text and "joint_state:" in text and "- description: ''" in text
    store.erase("C")
    assert store.names() == []
    assert store.path.read_text().strip() == "[]"


def test_errors_name_the_waypoint_and_the_alternatives(tmp_path: Path):
    store = WaypointStore(tmp_path / "waypoints.yaml")
    store.save(_waypoint("Home"))
    store.save(_waypoint("Away"))
    with pytest.raises(ConfigError, match=r"no waypoint named 'Hom'.*did you mean 'Home'"):
        store.get("Hom")
    with pytest.raises(ConfigError, match="already exists"):
        store.rename("Home", "Away")
    with pytest.raises(ConfigError, match="no waypoint named 'Nope'"):
        store.rename("Nope", "X")
    with pytest.raises(ConfigError, match="no waypoint named 'Nope'"):
        store.erase("Nope")
    with pytest.raises(ConfigError, match="2 joint names but 1 positions"):
        store.save(Waypoint("Bad", list(JOINTS), [1.0]))
    assert store.names() == ["Home", "Away"]


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        ("a: 1\n", 1, "is a YAML list"),
        ("- name: A\n  joint_state: {name: [a], position: [1, 2]}\n", 2, "1 joint names but 2 positions"),
        ("- joint_state: {}\n", 1, "non-empty string name"),
        ("- name: A\n  joint_state: {name: [a], position: [x]}\n", 2, "position must be a list of numbers"),
        ("- name: A\n  joint_state: 5\n", 2, "needs a joint_state"),
        (
            "- name: A\n  joint_state: {name: [], position: []}\n"
            "- name: A\n  joint_state: {name: [], position: []}\n",
            3,
            "two waypoints are named 'A' (lines 1 and 3)",
        ),
        ("- [\n", 2, "invalid YAML"),
    ],
)
def test_bad_waypoint_files_are_clear_errors(tmp_path: Path, text: str, line: int, words: str):
    path = tmp_path / "waypoints.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as caught:
        WaypointStore(path).names()
    assert str(caught.value).startswith(f"{path}:{line}:"), str(caught.value)
    assert words in str(caught.value)


def test_non_utf8_waypoints_file(tmp_path: Path):
    path = tmp_path / "waypoints.yaml"
    path.write_bytes(b"- name: caf\xe9\n")
    with pytest.raises(ConfigError, match="not UTF-8"):
        WaypointStore(path).names()


def test_concurrent_threads_never_lose_a_waypoint(tmp_path: Path):
    store_path = tmp_path / "waypoints.yaml"
    store_path.write_text("[]\n")
    threads, per_thread = 6, 8
    errors: list[BaseException] = []

    def writer(index: int) -> None:
        try:
            store = WaypointStore(store_path)  # each thread its own store, like separate requests
            for k in range(per_thread):
                store.save(_waypoint(f"t{index}-{k}", float(index), float(k)))
        except BaseException as error:  # reported below; a thread cannot raise into the test
            errors.append(error)

    workers = [threading.Thread(target=writer, args=(i,)) for i in range(threads)]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join(timeout=60)
    assert errors == []
    names = WaypointStore(store_path).names()
    assert len(names) == threads * per_thread
    assert set(names) == {f"t{i}-{k}" for i in range(threads) for k in range(per_thread)}


WRITER = """
import sys
from kinema.config import Waypoint, WaypointStore
store = WaypointStore(sys.argv[1])
prefix = sys.argv[2]
for k in range(int(sys.argv[3])):
    store.save(Waypoint(f"{prefix}-{k}", ["j"], [float(k)]))
    if k % 5 == 4:
        store.rename(f"{prefix}-{k}", f"{prefix}-{k}-renamed")
"""


def test_concurrent_processes_never_lose_a_waypoint(tmp_path: Path):
    store_path = tmp_path / "waypoints.yaml"
    processes, per_process = 3, 10
    running = [
        subprocess.Popen(
            [sys.executable, "-c", WRITER, str(store_path), f"p{i}", str(per_process)], stderr=subprocess.PIPE
        )
        for i in range(processes)
    ]
    for process in running:
        _, stderr = process.communicate(timeout=120)
        assert process.returncode == 0, stderr.decode()
    names = set(WaypointStore(store_path).names())
    expected = {
        f"p{i}-{k}-renamed" if k % 5 == 4 else f"p{i}-{k}"
        for i in range(processes)
        for k in range(per_process)
    }
    assert names == expected
    # readers never saw, and nothing left behind, a temporary file
    assert sorted(p.name for p in tmp_path.iterdir()) == ["waypoints.yaml", "waypoints.yaml.lock"]


def test_bundled_lab_sim_waypoints_parse_with_the_robot_joint_names():
    from kinema.config import Workspace, resolve_config

    resolved = resolve_config("lab_sim", Workspace.bundled_only())
    assert resolved.waypoints_path is not None
    store = WaypointStore(resolved.waypoints_path)
    names = store.names()
    assert names and len(names) == len(set(names))
    for waypoint in store.all():
        assert "linear_rail_joint" in waypoint.joint_names
        assert len(waypoint.positions) == len(waypoint.joint_names)


def test_an_unwritable_location_is_a_clear_error(tmp_path: Path):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    with pytest.raises(ConfigError, match="cannot create the folder of the waypoints file"):
        WaypointStore(blocker / "waypoints.yaml").save(_waypoint("A"))


# -- edits keep the file as its author wrote it -------------------------------------------------------------

COMMENTED_HEAD = "# lab_sim's waypoints, as MoveIt Pro saved them\n# (comments added by the test)\n"


@pytest.fixture
def moveit_pro_waypoints(shared_dir: Path, tmp_path: Path) -> Path:
    """MoveIt Pro's own lab_sim waypoints file, copied, with comments of the kinds people write."""
    source = shared_dir / "compat" / "moveit_pro" / "lab_sim" / "waypoints" / "ur_waypoints.yaml"
    lines = source.read_text().splitlines(keepends=True)
    home = lines.index("  name: Home\n")
    lines[home] = "  name: Home  # where every objective starts\n"
    lines.insert(home + 1, "# the poses below are for the pick and place demos\n")
    path = tmp_path / "ur_waypoints.yaml"
    path.write_text(COMMENTED_HEAD + "".join(lines))
    return path


def _changes(before: str, after: str) -> list[tuple[str, list[str], list[str]]]:
    """The changed line blocks between two texts: (kind, old lines, new lines)."""
    old, new = before.splitlines(), after.splitlines()
    matcher = difflib.SequenceMatcher(a=old, b=new, autojunk=False)
    return [(tag, old[i1:i2], new[j1:j2]) for tag, i1, i2, j1, j2 in matcher.get_opcodes() if tag != "equal"]


def test_saving_a_moveit_pro_waypoint_changes_only_its_changed_line(moveit_pro_waypoints: Path) -> None:
    store = WaypointStore(moveit_pro_waypoints)
    before = moveit_pro_waypoints.read_text()
    home = store.get("Home")
    rail = home.joint_names.index("linear_rail_joint")
    old_rail = home.positions[rail]
    home.positions[rail] = 0.25
    store.save(home)
    after = moveit_pro_waypoints.read_text()
    assert _changes(before, after) == [("replace", [f"    - {old_rail!r}"], ["    - 0.25"])]
    assert after.startswith(COMMENTED_HEAD)
    assert "  name: Home  # where every objective starts\n# the poses below" in after


def test_rename_erase_and_add_touch_only_their_own_lines(moveit_pro_waypoints: Path) -> None:
    store = WaypointStore(moveit_pro_waypoints)
    names = store.names()
    before = moveit_pro_waypoints.read_text()

    store.rename("Look at Table", "Look at the Table")
    renamed = moveit_pro_waypoints.read_text()
    assert _changes(before, renamed) == [
        ("replace", ["  name: Look at Table"], ["  name: Look at the Table"])
    ]

    store.erase("Park Far Right")
    erased = moveit_pro_waypoints.read_text()
    ((kind, removed, added),) = _changes(renamed, erased)
    assert kind == "delete" and added == []
    assert removed[0].startswith("- description:") and removed[-1] == "  name: Park Far Right"
    assert sum(line.startswith("- ") for line in removed) == 1  # the whole item, nothing around it

    store.save(_waypoint("Kinema", 0.1, 0.2))
    added_text = moveit_pro_waypoints.read_text()
    ((kind, _, appended),) = _changes(erased, added_text)
    assert kind == "insert" and added_text.startswith(erased)
    assert appended[0] == "- description: ''" and appended[-1] == "  name: Kinema"
    assert store.names() == [
        "Look at the Table" if n == "Look at Table" else n for n in names if n != "Park Far Right"
    ] + ["Kinema"]
    assert added_text.startswith(COMMENTED_HEAD)
    assert "  name: Home  # where every objective starts\n# the poses below" in added_text


def test_a_file_edited_by_hand_between_reads_is_read_again(tmp_path: Path) -> None:
    path = tmp_path / "waypoints.yaml"
    store = WaypointStore(path)
    store.save(_waypoint("above", 0.1, 0.2))
    assert store.get("above").positions == [0.1, 0.2]
    # Same length, written in place (same inode): the cache must not hide the change.
    text = path.read_text()
    path.write_text(text.replace("0.1", "0.7"))
    assert store.get("above").positions == [0.7, 0.2]
    path.write_text(text.replace("above", "below"))
    assert store.names() == ["below"]
    path.unlink()
    assert store.all() == []
    # A file that turned invalid is reported, not served from what was read before.
    path.write_text("- name: [broken\n")
    with pytest.raises(ConfigError):
        store.all()
