from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from kinema.config import ObjectiveLibrary, Workspace, resolve_config
from kinema.config.inheritance import LibraryPath
from kinema.config.objective_file import parse_objective_file
from kinema.config.objective_library import objective_file_name
from kinema.errors import ObjectiveError

MODEL = """  <TreeNodesModel>
    <SubTree ID="{id}">
      <input_port name="target" default="{{target}}">where to go</input_port>
      <output_port name="result" description="what happened"/>
      <inout_port name="count" default="3"/>
      <MetadataFields>
        <Metadata subcategory="Motion - Execute"/>
        <Metadata runnable="false"/>
      </MetadataFields>
    </SubTree>
  </TreeNodesModel>
"""


def _compat_library(shared_dir: Path) -> ObjectiveLibrary:
    folder = shared_dir / "compat" / "moveit_pro" / "objectives"
    return ObjectiveLibrary.from_libraries([LibraryPath("compat", folder, "compat", "compat")], ["compat"])


def test_compat_objectives_metadata_and_ports(shared_dir: Path):
    library = _compat_library(shared_dir)
    assert library.errors == []
    assert set(library.objectives) == {
        "3 Waypoints Pick and Place",
        "Close Gripper",
        "Look at Table",
        "Move to Joint State",
        "Move to Waypoint",
        "Open Gripper",
        "Reset MuJoCo Robot",
    }
    pick = library.get("3 Waypoints Pick and Place")
    assert pick.favorite and pick.runnable
    assert pick.subcategory == "Application - Basic Examples"
    assert pick.description.startswith("Basic example of repeatedly picking")
    assert pick.file.name == "3_waypoint_pick_and_place.xml"
    assert pick.line == 4  # where the multi-line <BehaviorTree tag starts
    move = library.get("Move to Waypoint")
    assert not move.runnable  # _subtreeOnly="true"
    assert move.subcategory == "Motion - Execute"
    assert [(p.name, p.direction, p.default) for p in move.ports][:3] == [
        ("waypoint_name", "input", ""),
        ("joint_group_name", "input", "manipulator"),
        ("link_padding", "input", "0.01"),
    ]
    joint = library.get("Move to Joint State")
    assert joint.ports[0].direction == "inout"
    assert joint.ports[0].default == "{target_joint_state}"
    assert library.get("Reset MuJoCo Robot").runnable
    assert not library.get("Open Gripper").favorite


def test_ports_metadata_and_descriptions_from_the_model(tmp_path: Path):
    path = tmp_path / "x.xml"
    path.write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Go"><AlwaysSuccess/></BehaviorTree>\n'
        f"{MODEL.format(id='Go')}</root>"
    )
    (info,) = parse_objective_file(path).objectives
    assert not info.runnable
    assert info.subcategory == "Motion - Execute"
    assert [(p.name, p.direction, p.default, p.description) for p in info.ports] == [
        ("target", "input", "{target}", "where to go"),
        ("result", "output", None, "what happened"),
        ("count", "inout", "3", ""),
    ]


def test_unknown_objective_suggests_close_ids(shared_dir: Path):
    with pytest.raises(ObjectiveError, match="did you mean 'Open Gripper'"):
        _compat_library(shared_dir).get("Open Griper")


def test_broken_files_are_reported_with_file_and_line_and_hide_nothing_else(ws):
    ws.config("robot")
    ws.objective("robot", "Good One")
    objectives = ws.root / "src" / "robot" / "objectives"
    (objectives / "broken.xml").write_text("<root>\n  <BehaviorTree ID='x'>\n    <Oops>\n</root>\n")
    (objectives / "latin1.xml").write_bytes(b"<root><BehaviorTree ID='caf\xe9'/></root>")
    (objectives / "no_tree.xml").write_text("<root>\n</root>\n")
    (objectives / "no_id.xml").write_text("<root>\n<BehaviorTree><AlwaysSuccess/></BehaviorTree>\n</root>\n")
    (objectives / "not_root.xml").write_text("<BehaviorTree ID='a'/>\n")
    (objectives / "notes.txt").write_text("not an objective")
    library = ObjectiveLibrary.load(resolve_config("robot", Workspace.discover(ws.root)))
    assert list(library.objectives) == ["Good One"]
    messages = sorted(str(error) for error in library.errors)
    assert len(messages) == 5
    assert any(m.startswith(f"{objectives / 'broken.xml'}:4: XML syntax error") for m in messages)
    assert any(m.startswith(f"{objectives / 'latin1.xml'}:1: the file is not UTF-8") for m in messages)
    assert any(
        m.startswith(f"{objectives / 'no_tree.xml'}:1: the file has no <BehaviorTree>") for m in messages
    )
    assert any(m.startswith(f"{objectives / 'no_id.xml'}:2: a <BehaviorTree> has no ID") for m in messages)
    assert any("not_root.xml:1: the top element is <BehaviorTree>" in m for m in messages)


def test_huge_objective_file_is_refused(ws, monkeypatch: pytest.MonkeyPatch):
    import kinema.config.objective_file as objective_file

    ws.config("robot")
    path = ws.objective("robot", "Big", body="<!--" + "x" * 5000 + "-->\n")
    monkeypatch.setattr(objective_file, "MAX_OBJECTIVE_BYTES", 1000)
    library = ObjectiveLibrary.load(resolve_config("robot", Workspace.discover(ws.root)))
    assert len(library.errors) == 1
    assert str(library.errors[0]).startswith(f"{path}: the file is ")
    assert "larger than the limit" in str(library.errors[0])
    assert library.objectives == {}


def test_most_derived_package_wins_and_the_shadowed_file_is_reported(ws):
    ws.config("base")
    ws.child("site", "base")
    ws.child("cell", "site")
    base_file = ws.objective("base", "Pick", _description="base pick")
    site_file = ws.objective("site", "Pick", _description="site pick")
    ws.objective("base", "Only Base")
    # the child's library is declared after the parent's, but rank comes from the chain, not the order
    library = ObjectiveLibrary.load(resolve_config("cell", Workspace.discover(ws.root)))
    pick = library.get("Pick")
    assert pick.description == "site pick"
    assert pick.package == "site"
    assert pick.shadows == [base_file]
    assert any(
        "'Pick' from site shadows the one in base" in n and str(site_file) in n for n in library.notices
    )
    assert library.get("Only Base").package == "base"


def test_two_files_of_one_library_with_one_id_are_a_warning_without_verbose(ws, capsys):
    from kinema.cli.main import main

    ws.config("robot")
    first = ws.objective("robot", "Wave", file="wave.xml", _description="first")
    copy = ws.objective("robot", "Wave", file="wave2.xml", _description="the copy")
    library = ObjectiveLibrary.load(resolve_config("robot", Workspace.discover(ws.root)))
    assert library.get("Wave").description == "the copy"  # files load in name order; the last wins
    assert len(library.warnings) == 1
    warning = library.warnings[0]
    assert warning.startswith(f"{copy}:3: objective 'Wave' is defined again")
    assert f"first at {first}:3" in warning
    assert main(["objective", "list", "-w", str(ws.root), "-c", "robot", "--no-check"]) == 0
    assert f"warning: {copy}:3: objective 'Wave' is defined again" in capsys.readouterr().err


def test_a_child_library_declared_first_still_wins_by_chain_position(ws):
    base = ws.root_data("base")
    # the root config lists a library of the child package before its own
    base["objectives"]["objective_library_paths"] = {
        "child_lib": {"package_name": "child", "relative_path": "objectives"},
        "base_lib": {"package_name": "base", "relative_path": "objectives"},
    }
    ws.config("base", base)
    ws.child("child", "base", own_library=False)
    ws.objective("base", "Same", _description="from base")
    ws.objective("child", "Same", _description="from child")
    library = ObjectiveLibrary.load(resolve_config("child", Workspace.discover(ws.root)))
    assert library.get("Same").description == "from child"


def test_duplicate_id_within_one_file_is_an_error(ws):
    ws.config("robot")
    objectives = ws.root / "src" / "robot" / "objectives"
    (objectives / "twice.xml").write_text(
        "<root>\n<BehaviorTree ID='A'><AlwaysSuccess/></BehaviorTree>\n"
        "<BehaviorTree ID='A'><AlwaysSuccess/></BehaviorTree>\n</root>"
    )
    library = ObjectiveLibrary.load(resolve_config("robot", Workspace.discover(ws.root)))
    assert "defined twice in this file (first on line 2)" in str(library.errors[0])


def test_main_tree_mismatch_and_bad_flags_are_notices(ws):
    ws.config("robot")
    objectives = ws.root / "src" / "robot" / "objectives"
    (objectives / "m.xml").write_text(
        '<root main_tree_to_execute="Other">'
        '<BehaviorTree ID="A" _favorite="maybe"><AlwaysSuccess/></BehaviorTree></root>'
    )
    library = ObjectiveLibrary.load(resolve_config("robot", Workspace.discover(ws.root)))
    assert library.get("A").favorite is False
    assert any("main_tree_to_execute='Other' names no <BehaviorTree>" in n for n in library.notices)
    assert any("_favorite='maybe' is not true or false" in n for n in library.notices)


def test_objective_file_names_follow_moveit_pro():
    assert (
        objective_file_name("Scan Scene - Multiple Point Clouds") == "scan_scene_-_multiple_point_clouds.xml"
    )
    assert objective_file_name("../../etc/passwd") == "etc_passwd.xml"
    assert objective_file_name("   ") == "objective.xml"


class TestSave:
    def _library(self, ws) -> ObjectiveLibrary:
        return ObjectiveLibrary.load(resolve_config("site", Workspace.discover(ws.root)))

    def test_saving_an_inherited_objective_shadows_it_in_the_own_library_keeping_metadata(self, ws):
        ws.config("base")
        ws.child("site", "base")
        original = ws.objective(
            "base", "Go", _description="go somewhere", _favorite="true", body=MODEL.format(id="Go")
        )
        info = self._library(ws).save(
            "Go", '<root BTCPP_format="4"><BehaviorTree ID="Go"><AlwaysFailure/></BehaviorTree></root>'
        )
        assert info.file == ws.root / "src" / "site" / "objectives" / "go.xml"
        assert info.package == "site"
        assert info.shadows == [original]
        assert info.description == "go somewhere"
        assert info.favorite
        assert not info.runnable
        assert [p.name for p in info.ports] == ["target", "result", "count"]
        assert "AlwaysFailure" in info.file.read_text()
        # a fresh load sees the same thing, and the parent's file is untouched
        reloaded = self._library(ws).get("Go")
        assert reloaded.file == info.file and reloaded.description == "go somewhere"
        assert "AlwaysSuccess" in original.read_text()

    def test_saving_an_own_objective_overwrites_its_file_atomically(self, ws):
        ws.config("base")
        ws.child("site", "base")
        path = ws.objective("site", "Mine", file="custom_name.xml", _description="mine")
        info = self._library(ws).save("Mine", '<BehaviorTree ID="Mine"><AlwaysFailure/></BehaviorTree>')
        assert info.file == path
        assert info.description == "mine"
        assert 'main_tree_to_execute="Mine"' in path.read_text()
        assert sorted(p.name for p in path.parent.iterdir()) == ["custom_name.xml"]  # no temp files left

    def test_new_explicit_metadata_wins_over_the_old(self, ws):
        ws.config("base")
        ws.child("site", "base")
        ws.objective("site", "Mine", _description="old")
        info = self._library(ws).save(
            "Mine", '<BehaviorTree ID="Mine" _description="new"><AlwaysSuccess/></BehaviorTree>'
        )
        assert info.description == "new"

    def test_save_refuses_xml_without_the_objective_and_bad_xml(self, ws):
        ws.config("base")
        ws.child("site", "base")
        library = self._library(ws)
        with pytest.raises(ObjectiveError, match=r"does not define the objective 'A'.*'B'"):
            library.save("A", '<root><BehaviorTree ID="B"><AlwaysSuccess/></BehaviorTree></root>')
        with pytest.raises(ObjectiveError, match="XML syntax error"):
            library.save("A", "<root><BehaviorTree ID='A'>")
        assert list((ws.root / "src" / "site" / "objectives").iterdir()) == []

    def test_save_without_an_own_library_says_how_to_add_one(self, ws):
        ws.config("base")
        ws.child("site", "base", own_library=False)
        with pytest.raises(ObjectiveError, match=r"no objective library of its own.*site_objectives"):
            self._library(ws).save("A", '<BehaviorTree ID="A"><AlwaysSuccess/></BehaviorTree>')

    def test_a_new_objective_does_not_overwrite_another_objectives_file(self, ws):
        ws.config("base")
        ws.child("site", "base")
        taken = ws.objective("site", "Other", file="a.xml")
        info = self._library(ws).save("A", '<BehaviorTree ID="A"><AlwaysSuccess/></BehaviorTree>')
        assert info.file.name == "a_2.xml"
        assert "Other" in taken.read_text()


def test_bundled_objectives_load_without_errors():
    library = ObjectiveLibrary.load(resolve_config("example_config", Workspace.bundled_only()))
    assert library.errors == []
    assert {"Open Gripper", "Close Gripper", "Open and Close Gripper"} <= set(library.objectives)
    assert library.get("Open and Close Gripper").package == "example_config"


def test_core_library_folder_listed_twice_loads_once(shared_dir: Path, ws):
    package = ws.config("picknik_ur_base_config")
    compat = shared_dir / "compat" / "moveit_pro" / "config" / "picknik_ur_base_config.yaml"
    shutil.copy(compat, package / "config" / "config.yaml")
    resolved = resolve_config("picknik_ur_base_config", Workspace.discover(ws.root), check_files=False)
    core_entries = [lib for lib in resolved.objective_library_paths if lib.package == "kinema_objectives"]
    assert len(core_entries) == 4
    library = ObjectiveLibrary.from_libraries(core_entries, resolved.chain)
    assert len(library.libraries) == 1


def test_saving_where_the_library_cannot_be_written_is_a_clear_error(ws, monkeypatch: pytest.MonkeyPatch):
    import os

    ws.config("base")
    ws.child("site", "base")
    library = ObjectiveLibrary.load(resolve_config("site", Workspace.discover(ws.root)))

    def refuse(source: str, destination: str) -> None:
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(os, "replace", refuse)
    with pytest.raises(ObjectiveError, match=r"a\.xml: cannot write the file: Permission denied"):
        library.save("A", '<BehaviorTree ID="A"><AlwaysSuccess/></BehaviorTree>')
    assert list((ws.root / "src" / "site" / "objectives").iterdir()) == []  # the temporary file is gone


def test_saving_one_objective_of_a_multi_objective_file_keeps_the_others(ws):
    ws.config("base")
    ws.child("site", "base")
    path = ws.root / "src" / "site" / "objectives" / "pair.xml"
    path.write_text(
        '<root BTCPP_format="4" main_tree_to_execute="First">\n'
        '  <BehaviorTree ID="First" _description="one"><AlwaysSuccess/></BehaviorTree>\n'
        '  <BehaviorTree ID="Second" _description="two"><AlwaysSuccess/></BehaviorTree>\n'
        '  <TreeNodesModel><SubTree ID="Second"><input_port name="x"/></SubTree></TreeNodesModel>\n'
        "</root>\n"
    )
    library = ObjectiveLibrary.load(resolve_config("site", Workspace.discover(ws.root)))
    saved = library.save("Second", '<BehaviorTree ID="Second"><AlwaysFailure/></BehaviorTree>')
    assert saved.file == path
    assert saved.description == "two" and [p.name for p in saved.ports] == ["x"]
    reloaded = ObjectiveLibrary.load(resolve_config("site", Workspace.discover(ws.root)))
    assert reloaded.get("First").description == "one"
    assert reloaded.get("First").file == path
    assert "AlwaysFailure" in path.read_text() and path.read_text().count("<BehaviorTree") == 2


def test_favorite_rules_are_noted(ws):
    ws.config("robot")
    ws.objective("robot", "Hidden Helper", _favorite="true", _subtreeOnly="true")
    for n in range(9):
        ws.objective("robot", f"Fav {n}", _favorite="true")
    library = ObjectiveLibrary.load(resolve_config("robot", Workspace.discover(ws.root)))
    assert any("'Hidden Helper' is a favorite but not runnable" in n for n in library.notices)
    assert any("package robot has 10 favorite objectives" in n for n in library.notices)


def test_a_factory_loaded_from_the_library_runs_the_child_s_version_of_an_overridden_objective(ws):
    # The parent's file still wins for "Helper", so it is loaded too; it also defines "Pick", which the
    # child overrides: the child's file must be registered after it (a factory keeps the last definition).
    from kinema.bt import BehaviorTreeFactory

    ws.config("base")
    ws.child("cell", "base")
    helper = '  <BehaviorTree ID="Helper"><AlwaysSuccess/></BehaviorTree>\n'
    base_file = ws.objective("base", "Pick", body=helper, _description="base pick")
    cell_file = ws.objective("cell", "Pick", _description="cell pick")
    library = ObjectiveLibrary.load(resolve_config("cell", Workspace.discover(ws.root)))
    assert library.get("Pick").file == cell_file and library.get("Helper").file == base_file
    factory = BehaviorTreeFactory()
    for path in library.files():
        factory.register_behavior_tree_from_file(path)
    for objective_id, info in library.objectives.items():
        assert factory.tree_definition(objective_id).filename == str(info.file), objective_id
